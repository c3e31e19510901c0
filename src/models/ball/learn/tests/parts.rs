//! Pieces of the learner on their own.
