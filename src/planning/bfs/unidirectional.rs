//! Plain BFS from the start, testing the goal when a state is generated.

use super::nodes::Tree;
use super::{check_budget, SearchLimits, SearchResult, SearchStats, SuccessorModel, BATCH};
use crate::error::Result;

/// Shortest plan from `start` to any state satisfying `is_goal`. `on_layer` sees the statistics after
/// every completed layer.
pub fn breadth_first<M: SuccessorModel>(
    model: &M,
    start: M::State,
    is_goal: impl Fn(&M::State) -> bool,
    limits: &SearchLimits,
    mut on_layer: impl FnMut(&SearchStats),
) -> Result<SearchResult> {
    let mut stats = SearchStats { stored: 1, ..SearchStats::default() };
    if is_goal(&start) {
        return Ok(SearchResult { plan: Some(Vec::new()), stats });
    }
    let k = model.num_actions();
    let mut tree = Tree::new(start);
    let mut batch = Vec::with_capacity(BATCH);
    let mut successors = Vec::with_capacity(BATCH * k);
    while tree.depth < limits.max_depth {
        let (begin, end) = (tree.layer_start, tree.len());
        if begin == end {
            break;
        }
        for chunk in (begin..end).step_by(BATCH) {
            let chunk_end = (chunk + BATCH).min(end);
            batch.clear();
            batch.extend((chunk..chunk_end).map(|i| tree.state(i)));
            successors.clear();
            model.expand(&batch, &mut successors);
            stats.expanded += batch.len() as u64;
            stats.generated += successors.len() as u64;
            for (j, &successor) in successors.iter().enumerate() {
                if let Some(node) = tree.insert(successor, chunk + j / k, j % k) {
                    if is_goal(&successor) {
                        stats.stored = tree.len() as u64;
                        stats.depth = tree.depth + 1;
                        stats.peak_memory_bytes = stats.peak_memory_bytes.max(tree.memory_bytes());
                        return Ok(SearchResult { plan: Some(tree.path_to(node)), stats });
                    }
                }
            }
            stats.stored = tree.len() as u64;
            stats.peak_memory_bytes = stats.peak_memory_bytes.max(tree.memory_bytes());
            check_budget(&stats, limits)?;
        }
        tree.layer_start = end;
        tree.depth += 1;
        stats.depth = tree.depth;
        on_layer(&stats);
    }
    Ok(SearchResult { plan: None, stats })
}
