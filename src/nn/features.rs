//! How an env state looks to a network: angles as (cos, sin), so states 2π apart are one input, then the
//! action. Shared by every learned dynamics model (PETS, the context model) at training and at planning.

/// Input features of one (state, action) pair.
pub fn features(state: &[f64], action: &[f64], angular: &[bool], out: &mut Vec<f32>) {
    for (x, is_angle) in state.iter().zip(angular) {
        if *is_angle {
            out.push(x.cos() as f32);
            out.push(x.sin() as f32);
        } else {
            out.push(*x as f32);
        }
    }
    out.extend(action.iter().map(|a| *a as f32));
}

pub fn feature_dim(angular: &[bool], action_dim: usize) -> usize {
    angular.iter().map(|a| if *a { 2 } else { 1 }).sum::<usize>() + action_dim
}
