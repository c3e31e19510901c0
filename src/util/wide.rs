//! Element-wise loops compiled for the widest vector unit the CPU has, chosen at run time, so that one binary
//! runs everywhere and still uses AVX-512 where it exists. The crate builds for baseline x86-64, whose SSE2
//! loops ran Adam, sums and activations at a quarter of an AVX-512 core's width (Adam alone was a fifth of a
//! PETS step on a Zen 5 core).
//!
//! The widths give the same bytes: Rust never fuses a multiply and an add it was not asked to fuse; add,
//! multiply, divide and square root round alike in every lane width; and LLVM does not reorder a
//! floating-point sum, so a loop vectorizes only across independent elements.
//!
//! [`widest_fn!`] writes the body out once per width, inside functions compiled for that width. A closure
//! handed to a function compiled for AVX-512 would not do: it is compiled on its own, for the baseline, and
//! LLVM rarely inlines a loop-sized body back into the wide caller. Closures written inside the body inherit
//! the width, and so do functions marked `#[inline(always)]`; other calls in the body run at the baseline.

/// Whether this CPU runs the AVX-512 copies.
#[inline(always)]
pub fn has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        // Every feature the copies are compiled for, though no CPU with AVX-512 F and VL lacks the rest.
        std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
            && std::arch::is_x86_feature_detected!("avx512bw")
            && std::arch::is_x86_feature_detected!("avx512dq")
            && has_avx2_fma()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Whether this CPU runs the AVX2 copies.
#[inline(always)]
pub fn has_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Clears the upper halves of the vector registers (`vzeroupper`) where the CPU has AVX. faer's matrix
/// kernels (private-gemm-x86's, written in assembly) return with them dirty, and on Intel cores every SSE
/// instruction after that, which is all of the baseline build's float code outside [`widest_fn!`] copies,
/// waits on them until something clears them: the context model's Gaussian log-likelihood over 28 000 values
/// took 3.9 ms after a faer product and 0.18 ms after this. Call it after each faer product or factorization.
#[inline]
pub fn clean_upper_state() {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx")]
        fn clear() {
            std::arch::x86_64::_mm256_zeroupper();
        }
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked just above).
            unsafe { clear() }
        }
    }
}

/// `widest_fn! { pub fn name[T: Bound](a: A, b: B) -> R { body } }` defines `name`, which runs `body` compiled
/// for AVX-512 or for AVX2 with FMA where the CPU has them, and for the baseline elsewhere. Parameters are
/// plain names; generics, if any, go in square brackets.
macro_rules! widest_fn {
    (
        $(#[$meta:meta])*
        $vis:vis fn $name:ident $([$($generics:tt)*])? ($($arg:ident : $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block
    ) => {
        $(#[$meta])*
        $vis fn $name $(<$($generics)*>)? ($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,fma")]
                fn on_avx512 $(<$($generics)*>)? ($($arg: $ty),*) $(-> $ret)? $body
                #[target_feature(enable = "avx2,fma")]
                fn on_avx2 $(<$($generics)*>)? ($($arg: $ty),*) $(-> $ret)? $body
                if $crate::util::wide::has_avx512() {
                    // SAFETY: the CPU has the features the copy is compiled for (checked just above).
                    return unsafe { on_avx512($($arg),*) };
                }
                if $crate::util::wide::has_avx2_fma() {
                    // SAFETY: as above.
                    return unsafe { on_avx2($($arg),*) };
                }
            }
            $body
        }
    };
}
pub(crate) use widest_fn;

#[cfg(test)]
mod tests {
    #[inline(always)]
    fn update(xs: &mut [f32]) {
        xs.iter_mut().for_each(|x| *x = 0.9 * *x + x.sqrt() / (*x + 1e-8));
    }

    widest_fn! {
        fn update_widest(xs: &mut [f32]) {
            update(xs)
        }
    }

    /// Division and square roots, the operations whose vector forms differ most from scalar code, give the
    /// scalar loop's bits on whichever path this CPU takes.
    #[test]
    fn the_wide_path_gives_the_scalar_bits() {
        let xs: Vec<f32> = (0..1000).map(|i| (i as f32 * 0.731).sin() * 3.0 + 3.5).collect();
        let mut scalar = xs.clone();
        for x in scalar.iter_mut() {
            update(std::slice::from_mut(x));
        }
        let mut wide = xs;
        update_widest(&mut wide);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&scalar), bits(&wide));
    }
}
