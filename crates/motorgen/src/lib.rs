//! Parametric, labelled meshes of small DC gear motors.
pub mod kernel;
