//! The in-process tests, one binary: the GPU opens once for all of them
//! (`common::gpu`), and a failure names its module (the part it checks) and
//! its test. Pure CPU checks (layouts, shaders, the collision reference, the
//! scene format) live here too.

mod common;

mod api_edits;
mod api_hostile;
mod capacity;
mod capsule_reference;
mod collide_reference;
mod determinism;
mod device_faults;
mod faults;
mod hull_reference;
mod input_track;
mod kept_pairs;
mod kernels;
mod layouts;
mod narrowphase_parity;
mod physics_capsules;
mod physics_contacts;
mod physics_core;
mod physics_hulls;
mod physics_joints;
mod physics_kinematic;
mod render;
mod scene_fuzz;
mod scene_validation;
mod shaders;
mod sleeping;
mod snapshot;
mod spawn;
mod stress;
mod subnormals;
mod user_input;
