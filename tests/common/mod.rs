pub mod compare;
pub mod host;
