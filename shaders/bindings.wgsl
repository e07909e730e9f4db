// The bind group every per-body pass of the step shares (src/step/mod.rs
// builds its layout). Two bind groups of it exist, A->B and B->A, built once.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> props: array<BodyProps>;
@group(0) @binding(2) var<storage, read> state_in: array<BodyState>;
@group(0) @binding(3) var<storage, read_write> state_out: array<BodyState>;
@group(0) @binding(4) var<storage, read_write> vel0: array<Velocity>;
