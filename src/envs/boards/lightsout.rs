//! LightsOut on an n×n board: pushing a field toggles it and its four neighbours; solved when all
//! lights are off.

use super::{field_at, BoardGame};
use crate::envs::embodiments::manipulator::BoardPoint;
use crate::error::{Error, Result};

/// Largest supported side length: n² fields must fit the 192-bit state.
pub const MAX_SIDE: usize = 13;

/// Field `r * n + c` is bit `r * n + c` (row-major), lit = 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct LightsOutState(pub [u64; 3]);

impl LightsOutState {
    pub fn get(&self, field: usize) -> bool {
        self.0[field / 64] >> (field % 64) & 1 == 1
    }

    pub fn set(&mut self, field: usize, on: bool) {
        let bit = 1u64 << (field % 64);
        if on {
            self.0[field / 64] |= bit;
        } else {
            self.0[field / 64] &= !bit;
        }
    }

    pub fn xor(self, other: LightsOutState) -> LightsOutState {
        LightsOutState([self.0[0] ^ other.0[0], self.0[1] ^ other.0[1], self.0[2] ^ other.0[2]])
    }

    pub fn count_lit(&self) -> u32 {
        self.0.iter().map(|w| w.count_ones()).sum()
    }

    /// The low 64 bits, for boards of at most 8×8 fields used as dense table indices.
    pub fn low_bits(&self) -> u64 {
        self.0[0]
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct LightsOut {
    n: usize,
    masks: Vec<LightsOutState>,
}

impl LightsOut {
    pub fn new(n: usize) -> Result<Self> {
        if !(2..=MAX_SIDE).contains(&n) {
            return Err(Error::config(format!("LightsOut board size {n} is not supported; expected 2 to {MAX_SIDE}")));
        }
        let masks = (0..n * n)
            .map(|field| {
                let (r, c) = (field / n, field % n);
                let mut mask = LightsOutState::default();
                mask.set(field, true);
                if r > 0 {
                    mask.set(field - n, true);
                }
                if r + 1 < n {
                    mask.set(field + n, true);
                }
                if c > 0 {
                    mask.set(field - 1, true);
                }
                if c + 1 < n {
                    mask.set(field + 1, true);
                }
                mask
            })
            .collect();
        Ok(LightsOut { n, masks })
    }

    pub fn side(&self) -> usize {
        self.n
    }

    pub fn fields(&self) -> usize {
        self.n * self.n
    }

    /// The board with exactly the given fields pressed from all-off.
    pub fn pressed(&self, moves: &[usize]) -> LightsOutState {
        moves.iter().fold(self.goal(), |s, &m| self.apply(s, m))
    }
}

impl BoardGame for LightsOut {
    type State = LightsOutState;

    fn name(&self) -> String {
        format!("lightsout-{0}x{0}", self.n)
    }

    fn side(&self) -> usize {
        self.n
    }

    fn num_moves(&self) -> usize {
        self.fields()
    }

    fn apply(&self, state: LightsOutState, mv: usize) -> LightsOutState {
        state.xor(self.masks[mv])
    }

    fn goal(&self) -> LightsOutState {
        LightsOutState::default()
    }

    fn symbolic(&self, state: LightsOutState) -> Vec<f64> {
        (0..self.fields()).map(|f| if state.get(f) { 1.0 } else { 0.0 }).collect()
    }

    fn decode_symbolic(&self, bits: &[f64]) -> Option<LightsOutState> {
        if bits.len() != self.fields() {
            return None;
        }
        let mut s = LightsOutState::default();
        for (f, &b) in bits.iter().enumerate() {
            s.set(f, b > 0.5);
        }
        Some(s)
    }

    fn canonical_string(&self, state: LightsOutState) -> String {
        (0..self.fields()).map(|f| if state.get(f) { "1" } else { "0" }).collect::<Vec<_>>().join(",")
    }

    fn parse(&self, text: &str) -> Result<LightsOutState> {
        let values: Vec<&str> = text.split(',').map(str::trim).collect();
        if values.len() != self.fields() {
            return Err(Error::config(format!(
                "board for {}: expected {} comma-separated values (0 or 1, row-major), got {}",
                self.name(),
                self.fields(),
                values.len()
            )));
        }
        let mut state = LightsOutState::default();
        for (field, v) in values.iter().enumerate() {
            match *v {
                "0" => {}
                "1" => state.set(field, true),
                other => {
                    return Err(Error::config(format!(
                        "board for {}: field {field} is '{other}'; expected 0 or 1",
                        self.name()
                    )))
                }
            }
        }
        Ok(state)
    }

    fn render(&self, state: LightsOutState) -> String {
        (0..self.n)
            .map(|r| {
                (0..self.n).map(|c| if state.get(r * self.n + c) { "■" } else { "·" }).collect::<Vec<_>>().join(" ")
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    fn move_target(&self, mv: usize) -> BoardPoint {
        let (r, c) = (mv / self.n, mv % self.n);
        [(c as f64 + 0.5) / self.n as f64, (r as f64 + 0.5) / self.n as f64]
    }

    fn move_at(&self, point: BoardPoint) -> Option<usize> {
        field_at(point, self.n).map(|(r, c)| r * self.n + c)
    }

    /// Each field pressed with probability 1/2: pressing is linear over GF(2), so a uniform press set gives
    /// every reachable board with the same probability.
    fn scramble(&self, rng: &mut rand_chacha::ChaCha8Rng) -> LightsOutState {
        use rand::Rng;
        let presses: Vec<usize> = (0..self.fields()).filter(|_| rng.random_bool(0.5)).collect();
        self.pressed(&presses)
    }

    fn move_name(&self, mv: usize) -> String {
        format!("push ({}, {})", mv / self.n, mv % self.n)
    }

    /// Not every board is solvable (on 5×5 only a quarter are): decided by linear algebra over GF(2).
    fn is_solvable(&self, state: LightsOutState) -> bool {
        super::gf2::solve(self, state).is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corner_push_toggles_three_fields_a_centre_push_five() {
        let game = LightsOut::new(5).unwrap();
        assert_eq!(game.apply(game.goal(), 0).count_lit(), 3);
        assert_eq!(game.apply(game.goal(), 12).count_lit(), 5);
        let s = game.apply(game.goal(), 12);
        assert_eq!(game.canonical_string(s), "0,0,0,0,0,0,0,1,0,0,0,1,1,1,0,0,0,1,0,0,0,0,0,0,0");
        assert_eq!(game.apply(s, 12), game.goal(), "each push is its own inverse");
    }

    #[test]
    fn parse_round_trips_and_rejects_bad_boards() {
        let game = LightsOut::new(5).unwrap();
        let s = game.pressed(&[3, 17]);
        assert_eq!(game.parse(&game.canonical_string(s)).unwrap(), s);
        let short = game.parse("0,1").unwrap_err().to_string();
        assert!(short.contains("expected 25") && short.contains("got 2"), "{short}");
        let bad = game.parse(&["2"; 25].join(",")).unwrap_err().to_string();
        assert!(bad.contains("field 0 is '2'"), "{bad}");
        assert!(LightsOut::new(14).is_err());
    }

    #[test]
    fn thirteen_by_thirteen_uses_all_three_words() {
        let game = LightsOut::new(13).unwrap();
        let s = game.apply(game.goal(), 168);
        assert!(s.get(168) && s.get(167) && s.get(155));
        assert_eq!(game.decode_symbolic(&game.symbolic(s)), Some(s));
    }

    #[test]
    fn pushes_land_on_the_field_under_the_point() {
        let game = LightsOut::new(5).unwrap();
        for mv in 0..25 {
            assert_eq!(game.move_at(game.move_target(mv)), Some(mv));
        }
    }
}
