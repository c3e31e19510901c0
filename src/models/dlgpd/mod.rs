//! DLGPD (thesis chapter 3): a VAE on pendulum images whose latent dynamics and reward are Gaussian
//! processes, controlled with CEM and adapted to changed dynamics by swapping the GPs' evidence.

pub mod config;
pub mod control;
pub mod data;
pub mod dynamics;
pub mod evidence;
pub mod grad;
pub mod job;
pub mod latent_gp;
pub mod loss;
pub mod model;
pub mod options;
pub mod prediction;
pub mod train;
pub mod vae;
