//! BFS from both ends at once, for models whose actions undo themselves: the search from the goal uses
//! the same successor model, and a plan is found where the two trees meet. Whole layers are expanded
//! one side at a time (the side with the smaller frontier), so the first meeting is a shortest plan.

use super::nodes::Tree;
use super::{check_budget, SearchLimits, SearchResult, SearchStats, SuccessorModel, BATCH};
use crate::error::{Error, Result};

pub fn bidirectional<M: SuccessorModel>(
    model: &M,
    start: M::State,
    goal: M::State,
    limits: &SearchLimits,
    mut on_layer: impl FnMut(&SearchStats),
) -> Result<SearchResult> {
    if !model.self_inverse() {
        return Err(Error::config(
            "bidirectional search needs a model whose actions undo themselves; use breadth-first search",
        ));
    }
    let mut stats = SearchStats { stored: 1, ..SearchStats::default() };
    if start == goal {
        return Ok(SearchResult { plan: Some(Vec::new()), stats });
    }
    let k = model.num_actions();
    let mut trees = [Tree::new(start), Tree::new(goal)];
    let mut batch = Vec::with_capacity(BATCH);
    let mut successors = Vec::with_capacity(BATCH * k);
    while trees[0].depth + trees[1].depth < limits.max_depth {
        let frontier = |t: &Tree<M::State>| t.len() - t.layer_start;
        let side = if frontier(&trees[0]) <= frontier(&trees[1]) { 0 } else { 1 };
        let (begin, end) = (trees[side].layer_start, trees[side].len());
        if begin == end {
            break;
        }
        for chunk in (begin..end).step_by(BATCH) {
            let chunk_end = (chunk + BATCH).min(end);
            batch.clear();
            batch.extend((chunk..chunk_end).map(|i| trees[side].state(i)));
            successors.clear();
            model.expand(&batch, &mut successors);
            stats.expanded += batch.len() as u64;
            stats.generated += successors.len() as u64;
            for (j, &successor) in successors.iter().enumerate() {
                let (parent, action) = (chunk + j / k, j % k);
                if let Some(meeting) = trees[1 - side].find(&successor) {
                    stats.depth = trees[0].depth + trees[1].depth + 1;
                    let plan = join(&trees, side, parent, action, meeting);
                    return Ok(SearchResult { plan: Some(plan), stats });
                }
                trees[side].insert(successor, parent, action);
            }
            stats.stored = (trees[0].len() + trees[1].len()) as u64;
            stats.peak_memory_bytes = stats.peak_memory_bytes.max(trees[0].memory_bytes() + trees[1].memory_bytes());
            check_budget(&stats, limits)?;
        }
        trees[side].layer_start = end;
        trees[side].depth += 1;
        stats.depth = trees[0].depth + trees[1].depth;
        on_layer(&stats);
    }
    Ok(SearchResult { plan: None, stats })
}

/// The plan through the meeting state. The goal tree's path is walked backwards, which is valid because
/// every action is its own inverse.
fn join<S: Copy + Eq + std::hash::Hash>(
    trees: &[Tree<S>; 2],
    side: usize,
    parent: usize,
    action: usize,
    meeting: usize,
) -> Vec<usize> {
    let (start_node, goal_node) = if side == 0 { (parent, meeting) } else { (meeting, parent) };
    let mut plan = trees[0].path_to(start_node);
    plan.push(action);
    plan.extend(trees[1].path_to(goal_node).into_iter().rev());
    plan
}
