//! TileSwap on a 3×3 board: a move swaps the chips on two adjacent fields (12 moves); solved when chip i
//! lies on field i (ascending row-major order).

use super::BoardGame;
use crate::envs::embodiments::manipulator::BoardPoint;
use crate::error::{Error, Result};

const SIDE: usize = 3;
const FIELDS: usize = SIDE * SIDE;
/// A push swaps a pair when it lands within this L1 distance of the pair's pivot (the shared edge's
/// midpoint): half a field, as in the original touch board.
pub const PIVOT_RADIUS_L1: f64 = (1.0 / SIDE as f64) / 2.0;

/// 4 bits per field: bits 4i..4i+3 hold the chip on field i.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TileSwapState(pub u64);

impl TileSwapState {
    pub fn chip(&self, field: usize) -> usize {
        ((self.0 >> (4 * field)) & 0xF) as usize
    }

    pub fn from_chips(chips: &[usize; FIELDS]) -> Self {
        TileSwapState(chips.iter().enumerate().fold(0, |acc, (f, &c)| acc | (c as u64) << (4 * f)))
    }

    pub fn chips(&self) -> [usize; FIELDS] {
        std::array::from_fn(|f| self.chip(f))
    }

    fn swap(self, a: usize, b: usize) -> Self {
        let (ca, cb) = ((self.0 >> (4 * a)) & 0xF, (self.0 >> (4 * b)) & 0xF);
        let diff = ca ^ cb;
        TileSwapState(self.0 ^ (diff << (4 * a)) ^ (diff << (4 * b)))
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct TileSwap {
    /// The two fields each move swaps: horizontal pairs row by row, then vertical pairs.
    pairs: Vec<(usize, usize)>,
    /// (pivot, move) in the authors' pivot order, which decides ties between equally near pivots.
    pivots: Vec<(BoardPoint, usize)>,
}

impl Default for TileSwap {
    fn default() -> Self {
        Self::new()
    }
}

impl TileSwap {
    pub fn new() -> Self {
        let mut pairs = Vec::with_capacity(12);
        for r in 0..SIDE {
            for c in 0..SIDE - 1 {
                pairs.push((r * SIDE + c, r * SIDE + c + 1));
            }
        }
        for r in 0..SIDE - 1 {
            for c in 0..SIDE {
                pairs.push((r * SIDE + c, (r + 1) * SIDE + c));
            }
        }
        let pivots = reference_pivots(&pairs);
        TileSwap { pairs, pivots }
    }

    pub fn pair(&self, mv: usize) -> (usize, usize) {
        self.pairs[mv]
    }
}

/// The pivots as `TileSwapTouchBoard._compute_pivot_points` (seads_envs/hybrid/touch_board.py) lists them:
/// fields in row-major order, for each first the pivot on its lower edge (a vertical swap), then the one
/// on its right edge (a horizontal swap). The coordinates use the same floating-point expressions
/// (`0.5·f + f·col`, `(row + 1)·f` with f = 1/3), so distances, and therefore ties, come out bit for bit as
/// in the original.
fn reference_pivots(pairs: &[(usize, usize)]) -> Vec<(BoardPoint, usize)> {
    let f = 1.0 / SIDE as f64;
    let move_of = |a: usize, b: usize| pairs.iter().position(|&p| p == (a, b)).expect("adjacent pair is a move");
    let mut pivots = Vec::with_capacity(pairs.len());
    for row in 0..SIDE {
        for col in 0..SIDE {
            let field = row * SIDE + col;
            if row != SIDE - 1 {
                let point = [0.5 * f + f * col as f64, (row + 1) as f64 * f];
                pivots.push((point, move_of(field, field + SIDE)));
            }
            if col != SIDE - 1 {
                let point = [f * (col + 1) as f64, 0.5 * f + row as f64 * f];
                pivots.push((point, move_of(field, field + 1)));
            }
        }
    }
    pivots
}

impl BoardGame for TileSwap {
    type State = TileSwapState;

    fn name(&self) -> String {
        "tileswap-3x3".into()
    }

    fn side(&self) -> usize {
        SIDE
    }

    fn num_moves(&self) -> usize {
        self.pairs.len()
    }

    fn apply(&self, state: TileSwapState, mv: usize) -> TileSwapState {
        let (a, b) = self.pairs[mv];
        state.swap(a, b)
    }

    fn goal(&self) -> TileSwapState {
        TileSwapState::from_chips(&std::array::from_fn(|i| i))
    }

    fn symbolic(&self, state: TileSwapState) -> Vec<f64> {
        let mut bits = vec![0.0; FIELDS * FIELDS];
        for field in 0..FIELDS {
            bits[field * FIELDS + state.chip(field)] = 1.0;
        }
        bits
    }

    fn decode_symbolic(&self, bits: &[f64]) -> Option<TileSwapState> {
        if bits.len() != FIELDS * FIELDS {
            return None;
        }
        let mut chips = [0usize; FIELDS];
        let mut seen = [false; FIELDS];
        for (field, row) in bits.chunks(FIELDS).enumerate() {
            let mut on = row.iter().enumerate().filter(|(_, &b)| b > 0.5).map(|(c, _)| c);
            let chip = on.next()?;
            if on.next().is_some() || seen[chip] {
                return None;
            }
            seen[chip] = true;
            chips[field] = chip;
        }
        Some(TileSwapState::from_chips(&chips))
    }

    fn canonical_string(&self, state: TileSwapState) -> String {
        state.chips().iter().map(|c| c.to_string()).collect::<Vec<_>>().join(",")
    }

    fn parse(&self, text: &str) -> Result<TileSwapState> {
        let name = self.name();
        let values: Vec<&str> = text.split(',').map(str::trim).collect();
        if values.len() != FIELDS {
            return Err(Error::config(format!(
                "board for {name}: expected {FIELDS} comma-separated chip numbers (0-8, one per field, row-major), got {}",
                values.len()
            )));
        }
        let mut chips = [0usize; FIELDS];
        let mut field_of_chip = [None; FIELDS];
        for (field, v) in values.iter().enumerate() {
            let chip: usize = v.parse().ok().filter(|c| *c < FIELDS).ok_or_else(|| {
                Error::config(format!("board for {name}: field {field} is '{v}'; expected a chip number 0-8"))
            })?;
            if let Some(first) = field_of_chip[chip] {
                return Err(Error::config(format!(
                    "board for {name}: chip {chip} appears on fields {first} and {field}; each chip 0-8 must appear once"
                )));
            }
            field_of_chip[chip] = Some(field);
            chips[field] = chip;
        }
        Ok(TileSwapState::from_chips(&chips))
    }

    fn render(&self, state: TileSwapState) -> String {
        (0..SIDE)
            .map(|r| (0..SIDE).map(|c| state.chip(r * SIDE + c).to_string()).collect::<Vec<_>>().join(" "))
            .collect::<Vec<_>>()
            .join("\n")
    }

    fn move_target(&self, mv: usize) -> BoardPoint {
        self.pivots.iter().find(|(_, m)| *m == mv).map(|(p, _)| *p).expect("every move has a pivot")
    }

    /// The nearest pivot in L1 (x distance + y distance, summed in that order as numpy does), if within
    /// half a field. Equally near pivots resolve to the first in the reference order, as numpy's argmin
    /// does; a strict `<` keeps the first.
    fn move_at(&self, point: BoardPoint) -> Option<usize> {
        if !(0.0..=1.0).contains(&point[0]) || !(0.0..=1.0).contains(&point[1]) {
            return None;
        }
        let mut best: Option<(f64, usize)> = None;
        for &(p, mv) in &self.pivots {
            let distance = (p[0] - point[0]).abs() + (p[1] - point[1]).abs();
            if best.is_none_or(|(d, _)| distance < d) {
                best = Some((distance, mv));
            }
        }
        best.filter(|&(d, _)| d <= PIVOT_RADIUS_L1).map(|(_, mv)| mv)
    }

    /// A uniform permutation (Fisher-Yates): adjacent swaps generate every permutation of the chips.
    fn scramble(&self, rng: &mut rand_chacha::ChaCha8Rng) -> TileSwapState {
        use rand::Rng;
        let mut chips: [usize; FIELDS] = std::array::from_fn(|i| i);
        for i in (1..FIELDS).rev() {
            chips.swap(i, rng.random_range(0..=i));
        }
        TileSwapState::from_chips(&chips)
    }

    fn move_name(&self, mv: usize) -> String {
        let (a, b) = self.pairs[mv];
        format!("swap fields {a}-{b}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twelve_self_inverse_swaps() {
        let game = TileSwap::new();
        assert_eq!(game.num_moves(), 12);
        let goal = game.goal();
        assert_eq!(game.canonical_string(goal), "0,1,2,3,4,5,6,7,8");
        for mv in 0..12 {
            let s = game.apply(goal, mv);
            assert_ne!(s, goal);
            assert_eq!(game.apply(s, mv), goal);
        }
        assert_eq!(game.canonical_string(game.apply(goal, 0)), "1,0,2,3,4,5,6,7,8");
    }

    #[test]
    fn symbolic_is_a_field_by_chip_one_hot_matrix() {
        let game = TileSwap::new();
        let s = game.apply(game.goal(), 0);
        let bits = game.symbolic(s);
        assert_eq!(bits.len(), 81);
        assert_eq!(bits[1], 1.0, "field 0 holds chip 1");
        assert_eq!(bits[9], 1.0, "field 1 holds chip 0");
        assert_eq!(bits.iter().sum::<f64>(), 9.0);
        assert_eq!(game.decode_symbolic(&bits), Some(s));
    }

    #[test]
    fn parse_rejects_duplicates_range_and_length() {
        let game = TileSwap::new();
        assert!(game.parse("0,1,2,3,4,5,6,7").unwrap_err().to_string().contains("got 8"));
        let dup = game.parse("0,1,2,3,4,5,6,7,7").unwrap_err().to_string();
        assert!(dup.contains("chip 7 appears on fields 7 and 8"), "{dup}");
        assert!(game.parse("0,1,2,3,4,5,6,7,9").unwrap_err().to_string().contains("'9'"));
        assert_eq!(game.parse("1, 0,2,3,4,5,6,7,8").unwrap(), game.apply(game.goal(), 0));
    }

    #[test]
    fn pushes_near_a_pivot_select_its_swap() {
        let game = TileSwap::new();
        for mv in 0..12 {
            let p = game.move_target(mv);
            assert_eq!(game.move_at(p), Some(mv));
            assert_eq!(game.move_at([p[0] + 0.08, p[1] + 0.08]), Some(mv));
        }
        assert_eq!(game.move_at([0.02, 0.02]), None, "a corner is farther than 1/6 from every pivot");
    }

    /// Exact float ties, and the authors' resolution (numpy argmin = first pivot in their order), checked
    /// with numpy 2.4 against the pivot list of `TileSwapTouchBoard`.
    #[test]
    fn equally_near_pivots_resolve_in_the_reference_order() {
        let game = TileSwap::new();
        let f = 1.0 / 3.0;
        // (1/6, 1/6): the pivots below field 0 and right of it are both exactly f/2 away; the reference
        // lists field 0's lower edge first, so the push swaps fields 0 and 3, not 0 and 1.
        let m = game.move_at([0.5 * f, 0.5 * f]).unwrap();
        assert_eq!(game.pair(m), (0, 3));
        // The corner shared by fields 0, 1, 3, 4: again an exact tie of the same two pivots.
        assert_eq!(game.pair(game.move_at([f, f]).unwrap()), (0, 3));
        // The centre field's middle: in floats the pivots below and right of field 4 (0.1666…63) beat the
        // ones above and left (0.1666…69); of the two, the lower edge comes first: fields 4 and 7.
        assert_eq!(game.pair(game.move_at([0.5, 0.5]).unwrap()), (4, 7));
        // (5/6, 5/6) is 0.16666666666666685 from its nearest pivots: just outside the radius.
        assert_eq!(game.move_at([5.0 / 6.0, 5.0 / 6.0]), None);
    }

    #[test]
    fn pivots_follow_the_reference_order_and_coordinates() {
        let game = TileSwap::new();
        let order: Vec<(usize, usize)> = game.pivots.iter().map(|&(_, m)| game.pair(m)).collect();
        assert_eq!(order[..4], [(0, 3), (0, 1), (1, 4), (1, 2)]);
        assert_eq!(order.len(), 12);
        assert_eq!(game.move_target(game.pivots[0].1), [1.0 / 6.0, 1.0 / 3.0]);
    }
}
