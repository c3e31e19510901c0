//! LightsOut as linear algebra over GF(2): pushes commute and are self-inverse, so a solution is a set of
//! fields x with A x = b, where A is the symmetric push matrix and b the lit fields. This is an
//! independent check of the planner's optimal depths, never used by the planner itself.

use super::{BoardGame, LightsOut, LightsOutState};

/// Rows of bits; column `fields` holds the right-hand side.
struct Matrix {
    rows: Vec<Vec<u64>>,
}

impl Matrix {
    fn get(&self, r: usize, c: usize) -> bool {
        self.rows[r][c / 64] >> (c % 64) & 1 == 1
    }

    fn flip(&mut self, r: usize, c: usize) {
        self.rows[r][c / 64] ^= 1 << (c % 64);
    }

    fn xor_row(&mut self, target: usize, source: usize) {
        let src = self.rows[source].clone();
        for (t, s) in self.rows[target].iter_mut().zip(src) {
            *t ^= s;
        }
    }
}

/// Minimal-push solution of a LightsOut board, or `None` when the board is not solvable (5×5 boards
/// outside the reachable quarter of the configuration space, for instance).
pub fn solve(game: &LightsOut, board: LightsOutState) -> Option<Vec<usize>> {
    let m = game.fields();
    let words = (m + 1).div_ceil(64);
    let mut a = Matrix { rows: vec![vec![0u64; words]; m] };
    for push in 0..m {
        let effect = game.apply(game.goal(), push);
        for field in 0..m {
            if effect.get(field) {
                a.flip(field, push);
            }
        }
    }
    for field in 0..m {
        if board.get(field) {
            a.flip(field, m);
        }
    }
    // Reduced row echelon form.
    let mut pivot_cols = Vec::new();
    let mut row = 0;
    for col in 0..m {
        let Some(p) = (row..m).find(|&r| a.get(r, col)) else { continue };
        a.rows.swap(row, p);
        for r in 0..m {
            if r != row && a.get(r, col) {
                a.xor_row(r, row);
            }
        }
        pivot_cols.push(col);
        row += 1;
    }
    if (row..m).any(|r| a.get(r, m)) {
        return None;
    }
    let is_pivot = {
        let mut v = vec![false; m];
        pivot_cols.iter().for_each(|&c| v[c] = true);
        v
    };
    let free: Vec<usize> = (0..m).filter(|&c| !is_pivot[c]).collect();
    // Each assignment of the free variables gives one solution; the nullity is small for the board
    // sizes in use (2 for 5×5, 8 for 9×9), so trying all of them finds the minimal one.
    if free.len() > 20 {
        return None;
    }
    let mut best: Option<Vec<usize>> = None;
    for assignment in 0u32..(1 << free.len()) {
        let mut x = vec![false; m];
        for (i, &f) in free.iter().enumerate() {
            x[f] = assignment >> i & 1 == 1;
        }
        for (r, &pc) in pivot_cols.iter().enumerate() {
            let mut v = a.get(r, m);
            for &f in &free {
                if x[f] && a.get(r, f) {
                    v = !v;
                }
            }
            x[pc] = v;
        }
        let pushes: Vec<usize> = (0..m).filter(|&i| x[i]).collect();
        if best.as_ref().is_none_or(|b| pushes.len() < b.len()) {
            best = Some(pushes);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solutions_solve_the_board() {
        let game = LightsOut::new(5).unwrap();
        let board = game.pressed(&[0, 6, 12, 24]);
        let pushes = solve(&game, board).unwrap();
        assert_eq!(game.pressed(&pushes), board);
        assert!(pushes.len() <= 4);
    }

    #[test]
    fn single_light_in_a_corner_is_unsolvable_on_5x5() {
        let game = LightsOut::new(5).unwrap();
        let mut board = game.goal();
        board.set(0, true);
        assert_eq!(solve(&game, board), None);
        let game4 = LightsOut::new(3).unwrap();
        let mut b3 = game4.goal();
        b3.set(0, true);
        assert!(solve(&game4, b3).is_some(), "3×3 is always solvable");
    }
}
