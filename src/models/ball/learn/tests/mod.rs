mod data;
mod forward;
mod gradients;
mod parts;
mod training;
