//! Speed of the ball EKF: one predict+update step (target < 2 µs) and a 1 s open-loop forecast, 180 steps
//! (target < 50 µs), far below the camera's 5.6 ms frame period.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use mbrl::data::ball_io::{Recording, RecordingInfo};
use mbrl::envs::ball::{simulate, CameraModel, LaunchParams, Orientation};
use mbrl::filtering::{forecast, forecast_means, predict, update, Vector};
use mbrl::models::ball::track::filter_recording;
use mbrl::models::ball::{initial_belief, BallModel, BallModelParams, Phase, SpinPrior};
use rand::SeedableRng;

// The binary runs on mimalloc (cmd/main.rs) and these figures are meant to be its: the library no longer
// chooses the process allocator, so each benchmark declares the same one.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn bench(c: &mut Criterion) {
    let model = BallModel::new(BallModelParams::thesis_learned()).unwrap();
    // High above the table: a free-flight step, the common case.
    let start =
        initial_belief(model.params(), [0.1, 2.8, 0.3], [0.102, 2.775, 0.305], 1, false, &SpinPrior::Uninformed)
            .unwrap();
    let m = Vector::<3>::new(0.104, 2.75, 0.31);

    c.bench_function("ball_ekf_predict_update", |b| {
        b.iter(|| {
            let prior = predict(&model, black_box(&start));
            update(&model, &prior, black_box(&m)).unwrap()
        })
    });

    // Just above the table and falling: the step contains the impact.
    let mut falling = start;
    falling.mean[2] = -0.461 + 0.02 + 0.005;
    falling.mean[5] = -3.0;
    c.bench_function("ball_ekf_predict_with_impact", |b| b.iter(|| predict(&model, black_box(&falling))));

    c.bench_function("ball_forecast_1s_with_covariance", |b| b.iter(|| forecast(&model, black_box(&start), 180)));
    c.bench_function("ball_forecast_1s_mean_only", |b| {
        b.iter(|| forecast_means(&model, black_box(&start.mean), Phase::BeforeImpact, 180))
    });

    // A whole simulated shot (about 200 frames with a bounce and lost frames), filtered from its first two
    // measurements, as `mbrl filter` does per trajectory.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let shot = simulate(&LaunchParams::sample(Orientation::Default, &mut rng), &CameraModel::default(), &mut rng);
    let recording = Recording {
        id: 0,
        frames: shot.frame_indices.clone(),
        positions: shot.positions.clone(),
        truth: None,
        info: RecordingInfo::default(),
    };
    c.bench_function(&format!("ball_filter_whole_trajectory_{}_frames", recording.frames.len()), |b| {
        b.iter(|| filter_recording(&model, black_box(&recording), None, &SpinPrior::Uninformed).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
