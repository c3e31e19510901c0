//! Protocols that reproduce the thesis' experiments and write reports (markdown + CSV + PNG).

pub mod ball;
pub mod ball_compare;
pub mod boards;
pub mod context;
pub mod dataset_report;
pub mod dlgpd;
pub mod dlgpd_action_response;
pub mod dlgpd_prediction;
pub mod num;
pub mod plot;
pub mod quick;
pub mod quick_claims;
pub mod quick_report;
pub mod seads;
pub mod stats;
pub mod summary;
pub mod swingup;
pub mod tradyn;
pub mod training;
pub mod verdict;
