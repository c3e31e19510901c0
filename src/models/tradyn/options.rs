//! What `mbrl train tradyn` asks for: the context model's settings, on unicycle data, with or without the
//! terrain lookup.

use std::path::{Path, PathBuf};

use crate::envs::{parse_env, EnvName};
use crate::error::{Error, Result};
use crate::models::context_net::options::{ContextOptions, Planned};
use crate::train::run_dir::default_out;

/// A TRADYN run on `data` (whose env is `data_env`), written to `out` (default `models/tradyn-terrain` or
/// `models/tradyn-no-terrain`). `env`, where given, must be the unicycle.
pub fn plan(
    options: &ContextOptions,
    data: &Path,
    data_env: &str,
    env: Option<&str>,
    terrain_lookup: bool,
    out: Option<PathBuf>,
) -> Result<Planned> {
    let parsed = parse_env(data_env)?;
    if !matches!(parsed, EnvName::Unicycle(_)) {
        return Err(Error::bad_file(
            data,
            format!(
                "holds '{data_env}' data; TRADYN learns the unicycle on terrain (`mbrl collect --env unicycle --maps DIR --instances N`)"
            ),
        ));
    }
    if let Some(env) = env.filter(|e| *e != "unicycle") {
        return Err(Error::config(format!("--env: TRADYN models the unicycle; got '{env}'")));
    }
    let config = options.config(&parsed)?;
    let variant = if terrain_lookup { "terrain" } else { "no-terrain" };
    Ok(Planned { config, out: out.unwrap_or_else(|| default_out(&format!("tradyn-{variant}"))) })
}
