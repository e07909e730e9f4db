//! The output files of INTERFACE.md section 3: the final state as JSON and
//! the trace as CSV.

use std::io::Write;

use crate::world::BodyOutput;
use crate::Error;

/// `--state-out`: the state after the last step.
pub fn state_json(step: u64, time: f64, bodies: &[BodyOutput]) -> String {
    let bodies: Vec<serde_json::Value> = bodies
        .iter()
        .map(|b| {
            serde_json::json!({
                "position": b.position,
                "orientation": b.orientation,
                "linear_velocity": b.linear_velocity,
                "angular_velocity": b.angular_velocity,
            })
        })
        .collect();
    let doc = serde_json::json!({ "step": step, "time": time, "bodies": bodies });
    serde_json::to_string_pretty(&doc).expect("plain JSON values always serialise")
}

/// The header line of a `--trace` CSV.
pub const TRACE_HEADER: &str = "step,time,body,px,py,pz,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz";

/// Writes one recorded step of a trace: a row per body.
pub fn write_trace_rows(out: &mut impl Write, step: u64, time: f64, bodies: &[BodyOutput]) -> std::io::Result<()> {
    for (i, b) in bodies.iter().enumerate() {
        let [px, py, pz] = b.position;
        let [qx, qy, qz, qw] = b.orientation;
        let [vx, vy, vz] = b.linear_velocity;
        let [wx, wy, wz] = b.angular_velocity;
        writeln!(out, "{step},{time},{i},{px},{py},{pz},{qx},{qy},{qz},{qw},{vx},{vy},{vz},{wx},{wy},{wz}")?;
    }
    Ok(())
}

/// Writes `text` to `path`, naming the path on failure.
pub fn write_file(path: &std::path::Path, text: &str) -> Result<(), Error> {
    std::fs::write(path, text).map_err(|source| Error::Io { path: path.display().to_string(), source })
}
