//! `mbrl list envs`: every env name the registry lists, with the sizes and time step of its simulator.

use super::Table;
use crate::envs::boards::spec::GAME_HELP;
use crate::envs::pendulum::variant::VARIANT_HELP;
use crate::envs::pendulum::PendulumVariant;
use crate::envs::terrain::generate_map;
use crate::envs::unicycle::UnicycleTerrain;
use crate::envs::{parse_env, EnvName, ENV_NAMES};
use crate::Result;

pub fn table() -> Result<Table> {
    let mut table = Table::new(&["NAME", "STATE", "ACTION", "DT (s)", "DESCRIPTION"]);
    for name in ENV_NAMES {
        let mut env = parse_env(name)?;
        // The sizes do not depend on the map; one generated map stands in for --map/--maps.
        if matches!(env, EnvName::Unicycle(_)) {
            env = env.with_terrain(UnicycleTerrain::new(vec![generate_map(0, 0)]))?;
        }
        let (state, action, dt) = match env.build() {
            Ok(sim) => {
                let spec = sim.spec();
                (spec.state_dim().to_string(), spec.action_dim().to_string(), format!("{}", spec.dt))
            }
            // Board sets, ball recordings and map sets are made by `collect`, never stepped.
            Err(_) => ("—".into(), "—".into(), "—".into()),
        };
        table.row(vec![name.to_string(), state, action, dt, describe(&env)]);
    }
    table.note("");
    table.note(format!("pendulum variants: {VARIANT_HELP}"));
    table.note(format!("board games: {GAME_HELP}; any of them played by a manipulator: <game>:cursor|reacher|jaco (jaco needs `make mujoco`)"));
    table.note("Gym's Pendulum-v0 is accepted as pendulum (same dynamics step for step).");
    Ok(table)
}

fn describe(env: &EnvName) -> String {
    let text = match env {
        EnvName::Pendulum(variant) => match variant {
            PendulumVariant::Standard => "gym's Pendulum-v0 swing-up (thesis ch. 3-4)",
            PendulumVariant::Mass(m) => return format!("pendulum with pole mass {m} (thesis 3.5.3)"),
            PendulumVariant::Inverted => "pendulum whose actions act reversed",
            PendulumVariant::Quadrant => {
                "pendulum with hidden per-quadrant actuator gains and signs per instance (thesis 4.5.3)"
            }
        },
        EnvName::Toy(_) => "linear toy system whose squashed action hides α (thesis eq. 4.40)",
        EnvName::MountainCar => "MountainCar over random Gaussian-bump terrain per instance (thesis eq. 4.41)",
        EnvName::Board(_) => "board game on its own: board sets (collect --boards) and solve-board",
        EnvName::Embodied(..) => "board game played by a manipulator (SEADS, thesis ch. 7)",
        EnvName::Ball => "table-tennis ball recorded by cameras (collect --trajectories; thesis ch. 6)",
        EnvName::Unicycle(_) => "TRADYN's unicycle robot on terrain maps (--map or --maps; thesis ch. 5)",
        EnvName::Terrain => "terrain map sets for the unicycle (collect --maps N)",
    };
    text.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_listed_env_parses_and_steppable_ones_have_sizes() {
        let table = table().unwrap();
        assert_eq!(table.names().collect::<Vec<_>>(), ENV_NAMES);
        for row in table.rows() {
            parse_env(&row[0]).unwrap();
        }
        let row = |name: &str| table.rows().iter().find(|r| r[0] == name).unwrap().clone();
        assert_eq!(row("pendulum")[1..4], ["2", "1", "0.05"]);
        assert_eq!(row("unicycle")[1..3], ["4", "2"]);
        assert_eq!(row("ball")[1], "—");
    }
}
