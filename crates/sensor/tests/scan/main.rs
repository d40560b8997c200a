//! Scans of analytic scenes, one module a topic.

mod colour;
mod edges;
mod filters;
mod geometry;
mod interreflection;
mod kit;
mod noise;
mod reflectance;
mod regions;
mod sensors;
mod wear;
mod zivid;
