//! Model-free reinforcement learning used inside model-based methods: SEADS learns its skill policies with
//! [`sac`].

pub mod sac;
