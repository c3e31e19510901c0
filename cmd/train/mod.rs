//! `mbrl train`'s options and work live in `mbrl::jobs::train`; what stays here needs the binary's clap
//! command.

pub mod alias;
