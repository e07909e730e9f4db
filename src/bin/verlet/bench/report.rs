//! The report of `verlet bench` as a terminal table and as CSV rows.

use super::median;
use super::results::{CaseResult, PeerResult, Report};
use crate::lavapipe::{Dispatch, INLINE_MAX_BODIES};

/// The peer's time over ours for each of our repetitions and the peer's
/// taken right after it (`PeerReps`), when there are several: how far the
/// ratio moves from one repetition to the next.
fn by_repetition(ours: &[f64], peer: &[f64]) -> String {
    if ours.len() < 2 || ours.len() != peer.len() {
        return String::new();
    }
    let each: Vec<String> = ours.iter().zip(peer).map(|(o, p)| format!("{:.2}x", p / o)).collect();
    each.join(", ")
}

fn fmt_ms(v: f64) -> String {
    if !v.is_finite() {
        "-".into()
    } else if v >= 100.0 {
        format!("{v:.1}")
    } else if v >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

fn fmt_rate(v: f64) -> String {
    if !v.is_finite() {
        "-".into()
    } else if v >= 1e6 {
        format!("{:.2} M", v / 1e6)
    } else {
        format!("{:.0} k", v / 1e3)
    }
}

/// Plain-text columns: the first left-aligned, the rest right-aligned
/// (numbers), two spaces apart.
fn columns(rows: &[Vec<String>]) -> String {
    let count = rows.iter().map(Vec::len).max().unwrap_or(0);
    let widths: Vec<usize> =
        (0..count).map(|k| rows.iter().filter_map(|r| r.get(k)).map(|c| c.chars().count()).max().unwrap_or(0)).collect();
    let mut s = String::new();
    for row in rows {
        let mut line = String::new();
        for (k, cell) in row.iter().enumerate() {
            let w = widths[k];
            if k == 0 {
                line.push_str(&format!("{cell:<w$}"));
            } else {
                line.push_str(&format!("  {cell:>w$}"));
            }
        }
        s.push_str(line.trim_end());
        s.push('\n');
    }
    s
}

/// The peer on its threads and on one, each against ours (empty without a peer).
fn peer_threads_table(r: &Report) -> String {
    use std::fmt::Write as _;
    let peers: Vec<(&CaseResult, &PeerResult)> = r.cases.iter().filter_map(|c| c.peer.as_ref().map(|p| (c, p))).collect();
    let mut s = String::new();
    if peers.is_empty() {
        return s;
    }
    let _ = writeln!(s, "\nrapier3d by threads (ms / ours: its ms/step over ours)\n");
    let mut rows = vec![["case", "ours ms/step", "threads", "rapier3d ms/step", "ms / ours", "1 thread ms/step", "ms / ours"]
        .map(String::from)
        .to_vec()];
    for (c, p) in peers {
        rows.push(vec![
            c.case.clone(),
            fmt_ms(c.median_ms_per_step),
            p.thread_count.to_string(),
            fmt_ms(p.median_ms_per_step),
            format!("{:.2}x", p.speedup),
            fmt_ms(p.one_thread_median_ms_per_step),
            format!("{:.2}x", p.one_thread_speedup),
        ]);
    }
    let _ = write!(s, "{}", columns(&rows));
    s
}

/// The report as plain text for a terminal: what was measured, in the
/// user's terms.
pub fn table(r: &Report) -> String {
    use std::fmt::Write as _;
    let cells = |v: &[&str]| v.iter().map(|c| c.to_string()).collect::<Vec<String>>();
    let peer = r.peer.split_whitespace().next().filter(|_| r.cases.iter().any(|c| c.peer.is_some()));
    let mut s = String::new();
    let _ = writeln!(s, "\nmachine:  {} ({} cores)", r.cpu, r.cores);
    let _ = writeln!(s, "adapter:  {}", r.adapter);
    let _ = writeln!(
        s,
        "limits:   largest scene {} bodies (storage binding {} B), {} B a body as a world is made; GPU opened in {:.2} s",
        r.max_bodies, r.max_storage_buffer_binding_size, r.bytes_per_body, r.gpu_open_s
    );
    let _ = writeln!(s, "shaders:  {}", r.shader_cache);
    let _ = writeln!(s, "peer:     {}", r.peer);
    let _ = writeln!(s, "solver:   {}", r.iterations);
    let _ = writeln!(s, "command:  {}", r.command);
    let inline: Vec<&str> = r.cases.iter().filter(|c| c.lavapipe == Some(Dispatch::Inline)).map(|c| c.case.as_str()).collect();
    if !inline.is_empty() {
        let _ = writeln!(
            s,
            "lavapipe: {} ran each dispatch on the submitting thread (at most {} bodies), the other cases on lavapipe's worker threads; LP_NUM_THREADS, when set, decides for all",
            inline.join(", "),
            INLINE_MAX_BODIES
        );
    }
    let busiest = r.cases.iter().filter_map(|c| c.load_avg).flatten().fold(0.0f64, f64::max);
    if busiest > r.cores as f64 + 0.5 {
        let _ = writeln!(
            s,
            "warning: the machine was busy (1-minute load average up to {busiest:.1} on {} cores): other work shared the CPU, so every time below is inflated",
            r.cores
        );
    }

    let mut head = cells(&["case", "bodies", "steps x reps", "start-up s", "ms/step", "body-steps/s", "GPU MiB", "B/body"]);
    if let Some(peer) = peer {
        head.extend([format!("{peer} ms/step"), format!("{peer} body-steps/s"), format!("{peer} ms / ours")]);
    }
    let mut rows = vec![head];
    for c in &r.cases {
        if let Some(why) = &c.skipped {
            rows.push(cells(&[&c.case, &c.bodies.to_string(), "skipped", "-", "-", "-", "-", "-"]));
            rows.push(vec![format!("  ({why})")]);
            continue;
        }
        let mut row = vec![
            c.case.clone(),
            c.bodies.to_string(),
            format!("{} x {}", c.steps, c.reps),
            format!("{:.2}", c.startup_s),
            fmt_ms(c.median_ms_per_step),
            fmt_rate(c.body_steps_per_s),
            format!("{:.1}", c.gpu_bytes as f64 / (1u64 << 20) as f64),
            format!("{:.0}", c.gpu_bytes_per_body),
        ];
        if peer.is_some() {
            row.extend(match &c.peer {
                Some(p) => [fmt_ms(p.median_ms_per_step), fmt_rate(p.body_steps_per_s), format!("{:.2}x", p.speedup)],
                None => ["-".into(), "-".into(), "-".into()],
            });
        }
        rows.push(row);
    }
    let _ = writeln!(s, "\nms/step: median of the repetitions, wall clock; B/body: GPU memory after the run, over the bodies");
    if let Some(peer) = peer {
        let _ = writeln!(s, "{peer} ms / ours: above 1x verlet is faster, below it {peer} is");
    }
    let _ = writeln!(s, "\n{}", columns(&rows).trim_end());
    for c in &r.cases {
        if let Some(p) = &c.peer {
            let each = by_repetition(&c.ms_per_step, &p.ms_per_step);
            if !each.is_empty() {
                let _ = writeln!(s, "{}: {} ms / ours by repetition (each after ours): {each}", c.case, peer.unwrap_or("peer"));
            }
        }
    }

    s.push_str(&peer_threads_table(r));
    let source = r.cases.iter().find_map(|c| c.stages.as_ref().map(|st| st.source.clone()));
    if let Some(source) = source {
        let mut rows = vec![cells(&[
            "case",
            "broadphase",
            "narrowphase",
            "integrate",
            "solve",
            "restitution",
            "sum of stages",
            "wall",
            "readback",
        ])];
        for c in &r.cases {
            let Some(st) = &c.stages else { continue };
            rows.push(vec![
                c.case.clone(),
                fmt_ms(st.broadphase),
                fmt_ms(st.narrowphase),
                fmt_ms(st.integrate),
                fmt_ms(st.solve),
                fmt_ms(st.restitution),
                fmt_ms(st.total),
                fmt_ms(c.median_ms_per_step),
                fmt_ms(c.readback_ms),
            ]);
        }
        let _ = writeln!(
            s,
            "\nper stage, ms a step ({source}, each pass timed on its own; wall: the repetitions' median; readback: every body's state read back once)\n"
        );
        let _ = write!(s, "{}", columns(&rows));
    }

    let mut rows = vec![cells(&["case", "sweeps in substeps", "first step ms", "later set-up s", "mean height m"])];
    if let Some(peer) = peer {
        rows[0].push(format!("{peer} mean height m"));
    }
    rows[0].extend(cells(&["most manifolds", "pools overflowed", "load avg start / end"]));
    for c in r.cases.iter().filter(|c| c.skipped.is_none()) {
        let mut row = vec![
            c.case.clone(),
            format!("{} in {}", c.iterations, c.substeps),
            fmt_ms(c.first_step_ms),
            format!("{:.2}", c.setup_s),
            format!("{:.3}", c.mean_height),
        ];
        if peer.is_some() {
            row.push(c.peer.as_ref().map_or("-".into(), |p| format!("{:.3}", p.mean_height)));
        }
        row.extend([
            c.max_contacts.to_string(),
            if c.contacts_overflowed { "yes" } else { "no" }.to_string(),
            c.load_avg.map_or("-".into(), |[a, b]| format!("{a:.1} / {b:.1}")),
        ]);
        rows.push(row);
    }
    let _ = writeln!(s, "\neach case after its last repetition\n");
    let _ = write!(s, "{}", columns(&rows));

    for c in &r.cases {
        if let Some(n) = &c.note {
            let _ = writeln!(s, "\nnote: {}: {n}", c.case);
        }
    }
    for (family, scaling) in [("cubes", &r.scaling), ("piles", &r.pile_scaling)] {
        if let Some(sc) = scaling {
            let pts: Vec<String> =
                sc.points.iter().map(|(n, ms)| format!("{n}: {:.1} ns/body-step", ms * 1e6 / *n as f64)).collect();
            let _ = writeln!(
                s,
                "\nscaling ({family}): time per step ~ bodies^{:.2} (log-log least squares over {}); cost per body-step spread {:.2}x",
                sc.exponent,
                pts.join(", "),
                sc.spread
            );
        }
    }
    if let Some(st) = &r.settled {
        let _ = writeln!(
            s,
            "\nsettled: {} with sleeping on: {} of {} bodies asleep after {} steps, {:.0} B/body (pools for {} pairs and {} manifolds), {} ms/step over the last 60",
            st.case,
            st.asleep,
            st.bodies,
            st.steps,
            st.gpu_bytes_per_body,
            st.pair_capacity,
            st.manifold_capacity,
            fmt_ms(st.last_ms_per_step)
        );
    }
    if !r.cold_start_s.is_empty() {
        let runs: Vec<String> = r.cold_start_s.iter().map(|t| format!("{t:.2}")).collect();
        let _ = writeln!(
            s,
            "\ncold start: `verlet run --builtin cubes --count 10 --steps 1`, whole process, MESA_SHADER_CACHE_DISABLE=true: {:.2} s (median of {} s)",
            median(&r.cold_start_s),
            runs.join(", ")
        );
    }
    if let (Some(setup), Some(ms)) = (r.render_setup_s, r.render_ms) {
        let _ = writeln!(
            s,
            "\nrender: the 1000-cube scene, landed, at 640 x 480 (4x MSAA, shadow map, image read back): {} ms a frame; renderer set-up {setup:.2} s",
            fmt_ms(ms)
        );
    }
    if let Some(d) = &r.dispatch {
        let _ = writeln!(
            s,
            "\ndispatches: {} a step for ten cubes at the default settings (two more above 1024 bodies, three above 2048, more with joints); they step in {} ms: about {:.0} us a dispatch before any work",
            d.dispatches_per_step,
            fmt_ms(d.ten_cubes_ms_per_step),
            d.us_per_dispatch
        );
        if let Some(i) = &d.inline {
            let _ = writeln!(
                s,
                "on lavapipe's submitting thread (LP_NUM_THREADS=0, as for scenes of at most {INLINE_MAX_BODIES} bodies): {} ms, about {:.0} us a dispatch",
                fmt_ms(i.ten_cubes_ms_per_step),
                i.us_per_dispatch
            );
        }
    }
    let asked: Vec<&str> = [
        (r.settled.is_none(), "--settle"),
        (r.cold_start_s.is_empty(), "--cold-start"),
        (r.render_ms.is_none(), "--render"),
        (r.dispatch.is_none(), "--dispatch-cost"),
    ]
    .into_iter()
    .filter_map(|(left_out, flag)| left_out.then_some(flag))
    .collect();
    if !asked.is_empty() {
        let _ = writeln!(s, "\nnot measured in this run: {} (or --all)", asked.join(", "));
    }
    s
}

/// One row per case.
pub fn csv(r: &Report) -> String {
    use std::fmt::Write as _;
    let mut s = String::from(
        "case,scene,bodies,steps,reps,skipped,startup_s,first_step_ms,setup_s,median_ms_per_step,body_steps_per_s,\
         gpu_bytes,gpu_bytes_per_body,stage_source,broadphase_ms,narrowphase_ms,integrate_ms,solve_ms,restitution_ms,\
         readback_ms,render_ms,integrate_ms_per_pass,copy_ms_per_pass,peer,peer_median_ms_per_step,peer_body_steps_per_s,speedup,adapter,\
         peer_one_thread_median_ms_per_step,one_thread_speedup\n",
    );
    let opt = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x}"));
    let quote = |t: &str| format!("\"{}\"", t.replace('"', "\"\""));
    for c in &r.cases {
        let st = c.stages.as_ref();
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            quote(&c.case),
            c.scene,
            c.bodies,
            c.steps,
            c.reps,
            quote(c.skipped.as_deref().unwrap_or("")),
            c.startup_s,
            c.first_step_ms,
            c.setup_s,
            c.median_ms_per_step,
            c.body_steps_per_s,
            c.gpu_bytes,
            c.gpu_bytes_per_body,
            st.map_or(String::new(), |x| x.source.clone()),
            opt(st.map(|x| x.broadphase)),
            opt(st.map(|x| x.narrowphase)),
            opt(st.map(|x| x.integrate)),
            opt(st.map(|x| x.solve)),
            opt(st.map(|x| x.restitution)),
            c.readback_ms,
            opt(c.render_ms),
            opt(c.integrate_ms_per_pass),
            opt(c.copy_ms_per_pass),
            quote(&c.peer.as_ref().map_or(String::new(), |p| format!("{} threads={}", p.engine, p.threads))),
            opt(c.peer.as_ref().map(|p| p.median_ms_per_step)),
            opt(c.peer.as_ref().map(|p| p.body_steps_per_s)),
            opt(c.peer.as_ref().map(|p| p.speedup)),
            quote(&r.adapter),
            opt(c.peer.as_ref().map(|p| p.one_thread_median_ms_per_step)),
            opt(c.peer.as_ref().map(|p| p.one_thread_speedup)),
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::case::blank;
    use crate::bench::results::{scaling, Settled, Stages};
    use verlet::bench::case;

    #[test]
    fn each_repetition_against_the_peers_after_it() {
        assert_eq!(by_repetition(&[40.0, 50.0, 42.0], &[44.0, 45.0, 42.0]), "1.10x, 0.90x, 1.00x");
        assert_eq!(by_repetition(&[40.0], &[44.0]), "", "one repetition: the speed-up says it all");
        assert_eq!(by_repetition(&[40.0, 41.0], &[44.0]), "", "not paired");
    }

    #[test]
    fn exponent_of_a_power_law() {
        let mk = |n: usize, ms: f64| CaseResult { scene: "cubes".into(), bodies: n, median_ms_per_step: ms, ..result_stub() };
        let rs = vec![mk(10_000, 2.0), mk(100_000, 20.0), mk(1_000_000, 200.0), mk(1_000, 99.0)];
        let s = scaling(&rs, "cubes").unwrap();
        assert!((s.exponent - 1.0).abs() < 1e-9, "{}", s.exponent);
        assert!((s.spread - 1.0).abs() < 1e-9);
        assert_eq!(s.points.len(), 3);
    }

    /// A pile case with a peer at `speedup` and, for 10k, a profile.
    fn pile(n: usize, ms: f64, speedup: f64, bytes_per_body: f64) -> CaseResult {
        let peer = PeerResult {
            engine: "rapier3d".into(),
            threads: "1".into(),
            thread_count: 1,
            sleeping: false,
            num_solver_iterations: 4,
            setup_s: 0.0,
            ms_per_step: vec![ms * speedup],
            median_ms_per_step: ms * speedup,
            body_steps_per_s: n as f64 / (ms * speedup * 1e-3),
            speedup,
            mean_height: 1.0,
            one_thread_ms_per_step: vec![ms * speedup],
            one_thread_median_ms_per_step: ms * speedup,
            one_thread_body_steps_per_s: n as f64 / (ms * speedup * 1e-3),
            one_thread_speedup: speedup,
        };
        let stages = (n == 10_000).then(|| Stages {
            source: "GPU timestamps".into(),
            steps: 10,
            broadphase: 2.0,
            narrowphase: 20.0,
            integrate: 2.0,
            solve: 30.0,
            restitution: 6.0,
            total: 60.0,
            passes: vec![
                ("pairs_count".into(), 8.0),
                ("pairs_write".into(), 1.0),
                ("narrowphase".into(), 6.0),
                ("narrowphase_ground".into(), 0.5),
                ("contact_lists".into(), 2.0),
                ("narrowphase_clip".into(), 2.5),
                ("solve_contacts".into(), 22.0),
            ],
        });
        CaseResult {
            case: format!("pile-{n}"),
            scene: "pile".into(),
            bodies: n,
            steps: 60,
            median_ms_per_step: ms,
            gpu_bytes_per_body: bytes_per_body,
            gpu_bytes_at_start: 1204 * n as u64,
            stages,
            peer: Some(peer),
            ..result_stub()
        }
    }

    fn report_of(cases: Vec<CaseResult>, max_bodies: u64, cold_start_s: Vec<f64>) -> Report {
        Report {
            command: String::new(),
            cpu: String::new(),
            cores: 2,
            adapter: String::new(),
            gpu_timestamps: true,
            max_bodies,
            max_storage_buffer_binding_size: 1 << 27,
            bytes_per_body: 1204,
            iterations: String::new(),
            peer: String::new(),
            gpu_open_s: 0.3,
            render_setup_s: None,
            render_ms: None,
            shader_cache: String::new(),
            sleeping: false,
            scaling: scaling(&cases, "cubes"),
            pile_scaling: scaling(&cases, "pile"),
            cold_start_s,
            settled: None,
            dispatch: None,
            cases,
        }
    }

    /// pile-10k brought to rest: `asleep` of its bodies, `bytes_per_body`.
    fn settled(asleep: usize, bytes_per_body: f64) -> Settled {
        Settled {
            case: "pile-10k".into(),
            bodies: 10_000,
            steps: 960,
            asleep,
            pairs: 12,
            manifolds: 9,
            pair_capacity: 64,
            manifold_capacity: 64,
            gpu_bytes: (bytes_per_body * 1e4) as u64,
            gpu_bytes_per_body: bytes_per_body,
            last_ms_per_step: 12.0,
        }
    }

    /// The terminal report: measurements in plain text, the peer's ratio,
    /// the settled pile and the cold start when measured, and nothing that
    /// grades the run.
    #[test]
    fn the_report_measures_and_does_not_grade() {
        let r = Report {
            settled: Some(settled(9_990, 448.0)),
            peer: "rapier3d 0.36 (single-threaded)".into(),
            ..report_of(vec![pile(1_000, 8.0, 0.65, 1241.0), pile(10_000, 60.0, 1.5, 1359.0)], 1_048_560, vec![1.9, 1.8, 2.4])
        };
        let text = table(&r);
        for word in ["target", "MISSED", "floor", "goal", "issue", "**", "|---"] {
            assert!(!text.contains(word), "{word:?} in {text}");
        }
        let row = text.lines().find(|l| l.starts_with("pile-10000 ")).unwrap_or_else(|| panic!("no pile-10k row: {text}"));
        assert!(row.contains("60.00") && row.contains("1.50x"), "{row}");
        assert!(text.contains("rapier3d ms / ours: above 1x verlet is faster"), "{text}");
        assert!(text.contains("settled: pile-10k with sleeping on: 9990 of 10000 bodies asleep"), "{text}");
        assert!(text.contains("1.90 s (median of 1.90, 1.80, 2.40 s)"), "{text}");
        assert!(text.contains("not measured in this run: --render, --dispatch-cost (or --all)"), "{text}");
        let json = serde_json::to_value(&r).unwrap();
        assert!(json.get("targets").is_none(), "{json}");
        assert!(!json.to_string().contains("issue"), "{json}");
    }

    #[test]
    fn columns_line_up() {
        let rows = vec![vec!["case".to_string(), "ms/step".into()], vec!["pile-1000".into(), "4.54".into()]];
        assert_eq!(columns(&rows), "case       ms/step\npile-1000     4.54\n");
    }

    fn result_stub() -> CaseResult {
        let c = case("pyramid");
        blank(&c, &c.scene(), 1, 1)
    }
}
