//! The random terrain of the MountainCar family (thesis eq. 4.41): a sum of Gaussian bumps, two of them fixed
//! walls at ±1 that keep the car's world a valley, the rest drawn per instance.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// h · exp(−½ (x − loc)² / width²).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bump {
    pub loc: f64,
    pub height: f64,
    pub width: f64,
}

impl Bump {
    pub fn height_at(&self, x: f64) -> f64 {
        let z = (x - self.loc) / self.width;
        self.height * (-0.5 * z * z).exp()
    }

    pub fn slope_at(&self, x: f64) -> f64 {
        -self.height_at(x) * (x - self.loc) / (self.width * self.width)
    }
}

/// The same for every instance, so only the bumps between them are hidden.
pub const WALLS: [Bump; 2] = [Bump { loc: -1.0, height: 0.5, width: 0.3 }, Bump { loc: 1.0, height: 0.5, width: 0.3 }];

/// How many grid points over [−1, 1] define the terrain's top for the reward (the authors' choice).
const TOP_GRID: usize = 500;

/// Every bump of one instance, the walls last. Recorded as the instance's hidden parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Terrain {
    pub bumps: Vec<Bump>,
}

impl Terrain {
    /// The walls alone: the terrain of an instance before one is drawn.
    pub fn walls_only() -> Self {
        Terrain { bumps: WALLS.to_vec() }
    }

    /// 2–7 bumps with loc ∼ U(−1.5, 1.5), height ∼ U(0.1, 0.3), width ∼ U(0.1, 0.5), then the walls.
    /// Locations, heights and widths are drawn as three blocks, in the order the authors' sampler used.
    pub fn sample(rng: &mut ChaCha8Rng) -> Self {
        let n = rng.random_range(2..=7usize);
        let locs: Vec<f64> = (0..n).map(|_| rng.random_range(-1.5..1.5)).collect();
        let heights: Vec<f64> = (0..n).map(|_| rng.random_range(0.1..0.3)).collect();
        let widths: Vec<f64> = (0..n).map(|_| rng.random_range(0.1..0.5)).collect();
        let mut bumps: Vec<Bump> =
            (0..n).map(|i| Bump { loc: locs[i], height: heights[i], width: widths[i] }).collect();
        bumps.extend(WALLS);
        Terrain { bumps }
    }

    pub fn height(&self, x: f64) -> f64 {
        self.bumps.iter().map(|b| b.height_at(x)).sum()
    }

    /// h'(x), in closed form.
    pub fn slope(&self, x: f64) -> f64 {
        self.bumps.iter().map(|b| b.slope_at(x)).sum()
    }

    /// The highest point on the grid the reward is measured against. On a grid, not the true maximum, because
    /// the published rewards were computed that way.
    pub fn grid_max_height(&self) -> f64 {
        (0..TOP_GRID)
            .map(|i| self.height(-1.0 + 2.0 * i as f64 / (TOP_GRID - 1) as f64))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn slope_matches_finite_differences() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for _ in 0..20 {
            let terrain = Terrain::sample(&mut rng);
            for i in 0..=40 {
                let x = -1.2 + 2.4 * i as f64 / 40.0;
                let h = 1e-6;
                let fd = (terrain.height(x + h) - terrain.height(x - h)) / (2.0 * h);
                assert!((terrain.slope(x) - fd).abs() < 1e-6, "x {x}: {} vs {fd}", terrain.slope(x));
            }
        }
    }

    #[test]
    fn samples_follow_the_thesis_ranges() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let mut counts = std::collections::BTreeSet::new();
        for _ in 0..300 {
            let t = Terrain::sample(&mut rng);
            let (random, walls) = t.bumps.split_at(t.bumps.len() - 2);
            assert_eq!(walls, WALLS);
            counts.insert(random.len());
            for b in random {
                assert!(
                    (-1.5..1.5).contains(&b.loc) && (0.1..0.3).contains(&b.height) && (0.1..0.5).contains(&b.width)
                );
            }
        }
        assert_eq!(counts.into_iter().collect::<Vec<_>>(), vec![2, 3, 4, 5, 6, 7]);
    }

    #[test]
    fn walls_make_a_symmetric_valley() {
        let t = Terrain::walls_only();
        assert_eq!(t.slope(0.0), 0.0);
        assert!(t.height(0.9) > t.height(0.5) && t.height(-0.9) > t.height(-0.5));
        assert!((t.grid_max_height() - t.height(1.0)).abs() < 1e-12, "the grid ends on the walls' peaks");
    }
}
