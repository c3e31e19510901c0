//! With the `mujoco` feature: an rpath to `.mujoco/lib` (filled by `make mujoco`), so the binary finds
//! libmujoco.so without LD_LIBRARY_PATH, and the Kinova model's folder compiled in. Without it: nothing.

use std::path::PathBuf;

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    if std::env::var_os("CARGO_FEATURE_MUJOCO").is_none() {
        return;
    }
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let mujoco = root.join(".mujoco");
    let lib = mujoco.join("lib");
    if !lib.join("libmujoco.so").is_file() {
        panic!("the `mujoco` feature needs {}: run `make mujoco` first", lib.join("libmujoco.so").display());
    }
    // The absolute path for binaries run where they were built; $ORIGIN-relative ones for a tree moved whole
    // (target/release/ and target/release/deps/ hold the binaries and test executables).
    for path in [lib.display().to_string(), "$ORIGIN/../../.mujoco/lib".into(), "$ORIGIN/../../../.mujoco/lib".into()] {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{path}");
    }
    println!("cargo::rustc-env=MBRL_KINOVA_DIR={}", mujoco.join("kinova").display());
}
