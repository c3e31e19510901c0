//! Terrain map sets (`--env terrain --maps N`), and the maps a unicycle drives on (`--map`, `--maps DIR`).

use std::path::{Path, PathBuf};

use super::{CollectOptions, CollectSummary};
use crate::data::terrain_set::{read_terrain_set, write_terrain_set_over};
use crate::envs::terrain::{TerrainMap, TerrainSplit};
use crate::envs::unicycle::UnicycleTerrain;
use crate::jobs::choices::SplitChoice;
use crate::jobs::{output_dir, Invocation, Job};
use crate::{refuse, Error, Result};

/// The maps `--map` / `--maps DIR --split S` name, loaded once for every instance.
pub(super) fn unicycle_terrain(
    map: Option<&Path>,
    maps: Option<&str>,
    split: Option<SplitChoice>,
) -> Result<UnicycleTerrain> {
    match (map, maps) {
        (Some(path), _) => {
            if split.is_some() {
                refuse!("--split picks maps of a set (--maps DIR); a single --map has no split");
            }
            Ok(UnicycleTerrain::new(vec![TerrainMap::read_png(path)?]))
        }
        (None, Some(dir)) => {
            let Some(split) = split else {
                refuse!("--maps {dir}: give --split train or --split test (models train on one half of a map set and are tested on the other)");
            };
            Ok(UnicycleTerrain::new(read_terrain_set(Path::new(dir), Some(TerrainSplit::from(split)))?))
        }
        (None, None) => Err(Error::config(crate::envs::registry::UNICYCLE_NEEDS_MAPS)),
    }
}

pub(super) fn prepare_maps(options: CollectOptions, invocation: &Invocation) -> Result<Job<'static, CollectSummary>> {
    let Some(count) = &options.maps else {
        refuse!("'terrain' makes map sets: give --maps N (e.g. --maps 100: 50 train and 50 test maps)");
    };
    let Ok(count) = count.parse::<usize>() else {
        refuse!("--maps: '{count}' is not a count; --env terrain takes the number of maps to make");
    };
    if options.map.is_some()
        || options.split.is_some()
        || options.actions.is_some()
        || options.instances.is_some()
        || options.images
    {
        refuse!("--env terrain takes only --maps N, --out DIR and --seed");
    }
    let out = output_dir("--out", options.out.as_deref(), || PathBuf::from("datasets/terrain"), invocation)?;
    let (seed, command_line, force) = (invocation.seed, invocation.command_line.clone(), invocation.force);
    Ok(Job::new("collect terrain", move |monitor| {
        write_terrain_set_over(&out, count, seed, &command_line, force, monitor)?;
        Ok(CollectSummary::Terrain { maps: count, out })
    }))
}
