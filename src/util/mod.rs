//! What every room may use and none owns: seeded random streams, atomic file writes, CSV tables. Nothing here
//! imports from another room, so any module can depend on it without creating a cycle.

pub mod alloc;
pub mod atomic;
pub mod bounded_read;
pub mod budget;
pub mod colored_noise;
pub mod domain;
pub mod fast_exp;
pub mod interrupt;
pub mod png;
pub mod rk45;
pub mod seeding;
pub mod suggest;
pub mod table;
pub mod warm_pool;
pub mod wide;
