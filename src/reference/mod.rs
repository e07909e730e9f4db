//! CPU twins of what the kernels compute, for tests: the same algorithm in
//! plain Rust, step by step like the WGSL, so a GPU result can be checked
//! against it and the algorithm itself can be checked on many random cases.

pub mod capsule;
pub mod collide;
pub mod hull;
