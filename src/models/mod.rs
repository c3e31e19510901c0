pub mod ball;
