mod filtering;
mod jacobian;
mod model;
