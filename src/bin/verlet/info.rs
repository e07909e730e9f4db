//! `verlet info`: the adapter in use, its limits, and what a body costs.

use verlet::gpu::Gpu;
use verlet::Error;

/// Prints the adapter, its limits and the memory a body takes.
pub fn info() -> Result<(), Error> {
    let gpu = Gpu::new()?;
    let i = &gpu.info;
    let l = &gpu.limits;
    outln!("adapter:  {}", i.name)?;
    outln!("backend:  {:?}", i.backend)?;
    outln!("type:     {:?}", i.device_type)?;
    outln!("driver:   {} {}", i.driver, i.driver_info)?;
    outln!("timestamp queries: {}", gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY))?;
    outln!("max storage buffer binding: {} bytes", l.max_storage_buffer_binding_size)?;
    outln!("max buffer size:            {} bytes", l.max_buffer_size)?;
    outln!("max storage buffers/stage:  {}", l.max_storage_buffers_per_shader_stage)?;
    outln!("max workgroups/dimension:   {}", l.max_compute_workgroups_per_dimension)?;
    use verlet::world::MANIFOLDS_PER_BODY;
    use verlet::world::{body_bytes, bytes_per_body, manifold_bytes, pair_bytes, PAIRS_PER_BODY, SHRINK_AFTER_STEPS};
    outln!(
        "GPU memory per body:        {} bytes as a world is made: {} its own, {} its share of the contact pools ({PAIRS_PER_BODY} pairs, {MANIFOLDS_PER_BODY} manifolds)",
        bytes_per_body(),
        body_bytes(),
        bytes_per_body() - body_bytes()
    )?;
    outln!(
        "contact pools:              {} bytes a pair, {} a manifold, by need: grown when a step fills three quarters, \
         made twice the need when {SHRINK_AFTER_STEPS} steps in a row fill less than a quarter (sleepers hold none)",
        pair_bytes(),
        manifold_bytes()
    )?;
    let (most_pairs, most_manifolds) = verlet::world::pair_capacities(&gpu, u64::MAX);
    outln!("contact pools at most:      {most_pairs} pairs, {most_manifolds} manifolds")?;
    outln!("largest scene:              {} bodies", verlet::world::max_bodies(&gpu))?;
    if crate::lavapipe::is_lavapipe(&gpu) {
        // lavapipe hands every dispatch to its worker threads, and that
        // hand-off is most of a small scene's step (docs/lavapipe.md)
        let threads =
            std::env::var("LP_NUM_THREADS").map_or("LP_NUM_THREADS unset: its default".into(), |t| format!("LP_NUM_THREADS={t}"));
        outln!(
            "software adapter:           lavapipe's worker threads take each dispatch ({threads}); \
             LP_NUM_THREADS=0 runs them on the submitting thread, faster for scenes of up to a few hundred bodies \
             (unset, `verlet run` and `verlet bench` choose it for scenes of at most {} bodies that draw no frames)",
            crate::lavapipe::INLINE_MAX_BODIES
        )?;
    }
    Ok(())
}
