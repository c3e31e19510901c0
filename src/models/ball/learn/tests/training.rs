//! Short training runs on simulated shots.
