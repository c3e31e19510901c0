//! "Did you mean …" for a name typed from a closed set (envs, games, variants, formats): one rule for every
//! such error, so a typo is answered the same way wherever it is made.

/// ` (did you mean 'NAME'?)` for the candidate nearest to `typed`, or nothing when none is near enough to be
/// a likely typo. Near: a Damerau–Levenshtein distance (case ignored) of at most a quarter of the typed
/// length (at least 1, at most 3), or `typed` the start of exactly one candidate.
pub fn did_you_mean<'a>(typed: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    match nearest(typed, candidates) {
        Some(name) => format!(" (did you mean '{name}'?)"),
        None => String::new(),
    }
}

/// The candidate [`did_you_mean`] suggests.
pub fn nearest<'a>(typed: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    if typed.is_empty() {
        return None;
    }
    let exact = typed;
    let typed = typed.to_lowercase();
    let allowed = typed.chars().count().div_ceil(4).clamp(1, 3);
    let mut best: Option<(usize, &str)> = None;
    let mut prefixed = Vec::new();
    for name in candidates {
        if name == exact {
            return None;
        }
        let lower = name.to_lowercase();
        if typed.chars().count() >= 3 && lower.starts_with(&typed) {
            prefixed.push(name);
        }
        let distance = strsim::damerau_levenshtein(&typed, &lower);
        if distance <= allowed && best.is_none_or(|(d, _)| distance < d) {
            best = Some((distance, name));
        }
    }
    best.map(|(_, name)| name).or(match prefixed[..] {
        [only] => Some(only),
        _ => None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const ENVS: [&str; 5] = ["pendulum", "pendulum:heavy", "mountaincar", "toy:inner", "tileswap:cursor"];

    #[test]
    fn typos_get_the_nearest_name() {
        assert_eq!(nearest("pendlum", ENVS), Some("pendulum"));
        assert_eq!(nearest("Pendulum", ENVS), Some("pendulum"));
        assert_eq!(nearest("pendulum:haevy", ENVS), Some("pendulum:heavy"));
        assert_eq!(nearest("tileswap:cursr", ENVS), Some("tileswap:cursor"));
        assert_eq!(did_you_mean("toy:iner", ENVS), " (did you mean 'toy:inner'?)");
    }

    #[test]
    fn a_unique_prefix_is_completed() {
        assert_eq!(nearest("mountain", ENVS), Some("mountaincar"));
        assert_eq!(nearest("toy", ENVS), Some("toy:inner"));
        // Both pendulum names start with "pend": no guess.
        assert_eq!(nearest("pend", ENVS), None);
    }

    #[test]
    fn unrelated_and_exact_names_get_no_suggestion() {
        assert_eq!(did_you_mean("cartpole", ENVS), "");
        assert_eq!(did_you_mean("ball", ENVS), "");
        assert_eq!(did_you_mean("", ENVS), "");
        assert_eq!(did_you_mean("pendulum", ENVS), "");
    }
}
