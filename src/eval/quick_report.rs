//! The printed lines and report.md of `eval quick`: per slice what it ran and found, the thesis figure or table
//! it reproduces and the verdict (`quick_claims`), and the ball comparison at every horizon and pose set.

use std::path::Path;

use super::quick::{
    DlgpdRun, QuickSummary, QUICK_CONTEXT_INSTANCES, QUICK_DLGPD_EVIDENCE_ROLLOUTS, QUICK_DLGPD_SWINGUP_STEPS,
    QUICK_DLGPD_TRAIN_STEPS, QUICK_SEADS_DEPTH, QUICK_TRADYN_INSTANCES, QUICK_TRADYN_MAPS, QUICK_TRADYN_TRAIN_STEPS,
};
use super::verdict::{format_p, Claim, ALPHA};
use crate::error::Result;
use crate::util::atomic::write_text;

/// One slice as printed and tabled.
pub struct Row {
    pub name: String,
    /// What ran and what it found.
    pub body: String,
    pub claim: Claim,
    /// The slice's own report, relative to the quick report.
    pub report: &'static str,
}

impl Row {
    fn line(&self) -> String {
        format!("{}; {}; see {}", self.body, self.claim.tail(), self.report)
    }
}

impl QuickSummary {
    /// The slices in run order, each judged from its numbers.
    pub fn rows(&self) -> Vec<Row> {
        let (sw, b, e, p, ball) = (&self.swingup, &self.boards, &self.embodied, &self.pets, &self.ball);
        let cm = |m: Option<f64>| m.map(|m| format!("{:.1} cm", 100.0 * m)).unwrap_or_else(|| "–".into());
        let mut rows = vec![
            Row {
                name: "pendulum swing-up, true model".into(),
                body: format!(
                    "pendulum swing-up (ground-truth model, CEM {}×{}×{}): {}/{} episodes succeeded",
                    sw.candidates, sw.horizon, sw.iterations, sw.successes, sw.episodes
                ),
                claim: sw.judge(),
                report: "pendulum-swingup/report.md",
            },
            Row {
                name: "board depth tables".into(),
                body: format!(
                    "board depth tables (LightsOut 5×5, TileSwap 3×3): {} depths, {} differ from thesis Table 7.1; \
                     train/test split of {} depths, {} differ from Table 7.2",
                    b.depths, b.differing, b.split_depths, b.split_differing
                ),
                claim: b.judge(),
                report: "boards/report.md",
            },
            Row {
                name: "LightsOut on the Reacher, scripted".into(),
                body: format!(
                    "LightsOut played by the Reacher's scripted controller, depths 1-5 (test split): {}/{} boards solved",
                    e.solved, e.boards
                ),
                claim: e.judge(),
                report: "lightsout-reacher/report.md",
            },
            Row {
                name: "PETS".into(),
                body: format!(
                    "PETS: ensemble of 5 trained {} steps on {} random transitions (validation MSE {}); swing-up planned \
                     on the learned model (CEM {}×{}×{}, {} TS-∞ particles): {}/{} episodes succeeded, mean return {:.1}",
                    p.train_steps,
                    p.transitions,
                    p.best_valid_loss.map(|v| format!("{v:.2e}")).unwrap_or_else(|| "–".into()),
                    p.candidates,
                    p.horizon,
                    p.iterations,
                    p.particles,
                    p.successes,
                    p.episodes,
                    p.mean_return
                ),
                claim: p.judge(),
                report: "pets/swingup/report.md",
            },
        ];
        let at_1s: Vec<String> = ball
            .horizons
            .iter()
            .filter(|c| (c.horizon_s - 1.0).abs() < 1e-9)
            .map(|c| {
                format!(
                    "{} {} vs {} (n = {}, {})",
                    c.group,
                    cm(Some(c.ekf_median)),
                    cm(Some(c.baseline_median)),
                    c.n,
                    format_p(c.p_value)
                )
            })
            .collect();
        let at_1s = if at_1s.is_empty() {
            format!("on unseen poses {} vs {}", cm(ball.trained), cm(ball.ridge))
        } else {
            at_1s.join(", ")
        };
        rows.push(Row {
            name: "ball EKF".into(),
            body: format!(
                "ball EKF: {} training steps lowered the loss {:.2} -> {:.2}; median prediction error of the trained EKF \
                 vs the ridge baseline at 1 s: {at_1s}; over 0.1-1.0 s: {}; oracle (the simulator's own constants) at \
                 1 s on unseen poses: {}",
                ball.train_steps,
                ball.first_loss,
                ball.last_loss,
                ball.horizon_summary(),
                cm(ball.oracle)
            ),
            claim: ball.judge(),
            report: "ball/report.md",
        });
        for c in &self.context {
            let entropy = c
                .entropy
                .map(|(informative, other)| format!("{informative:.2} vs {other:.2} nats"))
                .unwrap_or_else(|| "–".into());
            rows.push(Row {
                name: format!("Explore the Context, {}", c.env),
                body: format!(
                    "Explore the Context, {name}: context model (small preset, {} steps on {QUICK_CONTEXT_INSTANCES} \
                     instance pairs); one calibration transition in {} unseen contexts: prediction MSE random {:.2e}, \
                     open-loop EIG {:.2e} (Wilcoxon one-sided {}); entropy of q(β) after one informative vs \
                     non-informative action {entropy}",
                    c.train_steps,
                    c.contexts,
                    c.mse_random,
                    c.mse_open_loop,
                    format_p(c.p_value),
                    name = c.env,
                ),
                claim: c.judge(),
                report: if c.env == "toy:inner" { "toy-inner/eval/report.md" } else { "toy-outer/eval/report.md" },
            });
        }
        let sd = &self.seads;
        rows.push(Row {
            name: "SEADS, tileswap:cursor".into(),
            body: format!(
                "SEADS, tileswap:cursor (small preset, {} env steps, no game reward): the skills cover {}/{} moves; \
                 {}/{} test boards of depth 1-{QUICK_SEADS_DEPTH} solved by planning over the learned forward model",
                sd.env_steps, sd.distinct_moves, sd.moves, sd.solved, sd.boards
            ),
            claim: sd.judge(),
            report: "seads-tileswap-cursor/eval/report.md",
        });
        let describe = |run: &Option<DlgpdRun>| {
            run.as_ref()
                .map(|o| {
                    format!("return {:.1}, {}", o.total_return, if o.success { "swung up" } else { "not swung up" })
                })
                .unwrap_or_else(|| "not run".into())
        };
        let d = &self.dlgpd;
        rows.push(Row {
            name: "DLGPD".into(),
            body: format!(
                "DLGPD (small preset: MLP VAE on pole angles instead of images, {QUICK_DLGPD_TRAIN_STEPS} steps on {} \
                 random transitions of the standard pendulum), inverted-action pendulum, no retraining, \
                 {QUICK_DLGPD_SWINGUP_STEPS} steps, {} run per setting: with {QUICK_DLGPD_EVIDENCE_ROLLOUTS} matching \
                 evidence rollouts {}; with the standard pendulum's evidence {}",
                d.transitions,
                d.runs_per_setting,
                describe(&d.matching),
                describe(&d.mismatching)
            ),
            claim: d.judge(),
            report: "dlgpd/eval/report.md",
        });
        let t = &self.tradyn;
        let per_variant: Vec<String> = t
            .variants
            .iter()
            .map(|v| {
                format!(
                    "{} energy {:.2} / distance {:.0} mm / failed {}",
                    v.variant,
                    v.median_energy,
                    v.median_distance * 1000.0,
                    v.failures
                )
            })
            .collect();
        rows.push(Row {
            name: "TRADYN".into(),
            body: format!(
                "TRADYN: tiny models with and without terrain lookup ({QUICK_TRADYN_TRAIN_STEPS} steps on \
                 {QUICK_TRADYN_INSTANCES} unicycle pairs over {} train maps), {} navigation tasks on test maps, 30 \
                 steps, CEM 100×4 (medians): {}; `make repro-tradyn` runs the medium scale",
                QUICK_TRADYN_MAPS.div_ceil(2),
                t.tasks,
                per_variant.join("; ")
            ),
            claim: t.judge(),
            report: "tradyn/eval/report.md",
        });
        rows
    }

    /// One line per slice, as printed and listed in report.md: what ran, what it found, "target: …; verdict: …".
    pub fn lines(&self) -> Vec<String> {
        self.rows().iter().map(Row::line).collect()
    }

    /// The summary with every slice's claim filled in, as summary.json records it.
    pub fn judged(mut self) -> QuickSummary {
        self.swingup.claim = Some(self.swingup.judge());
        self.boards.claim = Some(self.boards.judge());
        self.embodied.claim = Some(self.embodied.judge());
        self.pets.claim = Some(self.pets.judge());
        self.ball.claim = Some(self.ball.judge());
        for c in &mut self.context {
            c.claim = Some(c.judge());
        }
        self.seads.claim = Some(self.seads.judge());
        self.dlgpd.claim = Some(self.dlgpd.judge());
        self.tradyn.claim = Some(self.tradyn.judge());
        self
    }
}

impl std::fmt::Display for QuickSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "{}", self.lines().join("\n"))
    }
}

fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// Writes the quick report.md of `summary` into `dir` (each slice's own report is in its subdirectory).
pub fn render(summary: &QuickSummary, dir: &Path) -> Result<()> {
    let rows = summary.rows();
    let mut md = format!(
        "# mbrl quick reproduction\n\n\
         Small-scale runs of each implemented method, each set against the thesis figure or table it reproduces.\n\n\
         Verdicts are reached from each run's own numbers by one rule. Every claim splits into parts: a one-sided test \
         in the thesis' direction (a rate the thesis reports as 100 % against a coin flip, exact binomial; or a paired \
         Wilcoxon signed-rank test), or an exact check of a quantity computed in full. A part passes with p < {ALPHA} \
         in the thesis' direction. **reproduced**: every part passes. **not at this scale**: some part that could \
         reach p < {ALPHA} with its n does not (or an exact check fails). **smoke test only**: otherwise, i.e. some \
         part's n is too small for p < {ALPHA} to be possible at all (one run per setting, four tasks), or the slice \
         runs something other than the thesis' method.\n\n\
         | slice | thesis target | thesis reports | this run | scale | n, test | verdict |\n\
         |---|---|---|---|---|---|---|\n"
    );
    for r in &rows {
        let c = &r.claim;
        let test = match (&c.n, &c.test) {
            (Some(n), Some(test)) => format!("n = {n}, {test}, {}", format_p(c.p_value)),
            (_, None) => "exact, no test".into(),
            (None, Some(test)) => test.clone(),
        };
        md.push_str(&format!(
            "| [{}]({}) | {} | {} | {} | {} | {} | **{}**: {} |\n",
            cell(&r.name),
            r.report,
            cell(&c.target),
            cell(&c.thesis),
            cell(&c.ours),
            cell(&c.scale),
            cell(&test),
            c.verdict,
            cell(&c.reason)
        ));
    }
    let ball = &summary.ball;
    if !ball.horizons.is_empty() {
        md.push_str(
            "\n## Ball: trained EKF vs ridge baseline at every horizon\n\n\
             Thesis Fig. 6.4 compares at 1 s on default and unseen launcher poses, Fig. 6.6 at 0.1-1.0 s on unseen \
             poses. Medians over the test shots; p: one-sided paired Wilcoxon signed-rank test that the EKF's per-shot \
             error is lower (a failed prediction ranks last). `oracle` runs the simulator's own constants (Table C.1): \
             a bound, not a competitor.\n\n\
             | poses | horizon [s] | n | EKF [cm] | ridge [cm] | oracle [cm] | p (EKF lower) | lower median |\n\
             |---|---|---|---|---|---|---|---|\n",
        );
        for c in &ball.horizons {
            md.push_str(&format!(
                "| {} | {:.1} | {} | {:.1} | {:.1} | {} | {} | {} |\n",
                c.group,
                c.horizon_s,
                c.n,
                100.0 * c.ekf_median,
                100.0 * c.baseline_median,
                c.oracle_median.map(|m| format!("{:.1}", 100.0 * m)).unwrap_or_else(|| "–".into()),
                format_p(c.p_value).trim_start_matches("p = "),
                if c.ekf_lower() { "EKF" } else { "**ridge**" }
            ));
        }
        md.push_str(&format!("\n{}.\n", ball.horizon_summary()));
    }
    md.push_str("\n## As printed\n\n");
    for r in &rows {
        md.push_str(&format!("- {}\n", r.line()));
    }
    write_text(&dir.join("report.md"), &md)
}
