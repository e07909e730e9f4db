//! `verlet bench --plot FILE.svg`: the report as a chart. Left, ms per step
//! against bodies on log axes, ours and the peer's, one line per family of
//! cases (pile-1k, pile-10k, ... make one); right, each case's step split
//! into its parts (GPU timestamps), stacked. SVG only: its text is left to
//! the viewer's fonts, so drawing it needs no font files.

use super::results::Report;
use plotters::prelude::*;

/// One case as the chart shows it.
pub struct Row {
    pub case: String,
    pub bodies: usize,
    /// Ours, median ms per step.
    pub ours_ms: f64,
    /// The peer's (rapier3d), where it ran.
    pub peer_ms: Option<f64>,
    /// ms per step of broadphase, narrowphase, integrate, solve, restitution.
    pub parts: Option<[f64; 5]>,
}

const PARTS: [&str; 5] = ["broadphase", "narrowphase", "integrate", "solve", "restitution"];
const PART_COLOURS: [RGBColor; 5] =
    [RGBColor(120, 120, 120), RGBColor(214, 39, 40), RGBColor(44, 160, 44), RGBColor(31, 119, 180), RGBColor(148, 103, 189)];
const FAMILY_COLOURS: [RGBColor; 4] =
    [RGBColor(31, 119, 180), RGBColor(214, 39, 40), RGBColor(44, 160, 44), RGBColor(255, 127, 14)];

/// The cases of a report that ran.
pub fn rows(report: &Report) -> Vec<Row> {
    report
        .cases
        .iter()
        .filter(|c| c.skipped.is_none() && c.median_ms_per_step > 0.0)
        .map(|c| Row {
            case: c.case.clone(),
            bodies: c.bodies,
            ours_ms: c.median_ms_per_step,
            peer_ms: c.peer.as_ref().map(|p| p.median_ms_per_step).filter(|&ms| ms > 0.0),
            parts: c.stages.as_ref().map(|s| [s.broadphase, s.narrowphase, s.integrate, s.solve, s.restitution]),
        })
        .collect()
}

/// A body count as people write it: 500, 10k, 1.5M.
fn count(n: f64) -> String {
    let (value, unit) = if n >= 1e6 {
        (n / 1e6, "M")
    } else if n >= 1e3 {
        (n / 1e3, "k")
    } else {
        (n, "")
    };
    let digits = if value >= 10.0 || value.fract().abs() < 1e-9 { 0 } else { 1 };
    format!("{value:.digits$}{unit}")
}

/// A case's family: its name without a size suffix ("pile-10k" -> "pile").
fn family(case: &str) -> &str {
    match case.rsplit_once('-') {
        Some((head, size)) if size.trim_end_matches(['k', 'm']).chars().all(|c| c.is_ascii_digit()) && !size.is_empty() => head,
        _ => case,
    }
}

/// The chart as SVG text. `title` heads it (the adapter, the machine);
/// `peer` names the other engine.
pub fn svg(title: &str, peer: &str, rows: &[Row]) -> Result<String, String> {
    if rows.is_empty() {
        return Err("no case ran: nothing to plot".into());
    }
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (1200, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root.titled(title, ("sans-serif", 18)).map_err(|e| e.to_string())?;
        let (left, right) = root.split_horizontally(600);
        scaling_chart(&left, peer, rows).map_err(|e| e.to_string())?;
        parts_chart(&right, rows).map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(text)
}

type Area<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;
type DrawResult = Result<(), DrawingAreaErrorKind<<SVGBackend<'static> as DrawingBackend>::ErrorType>>;

/// ms per step against bodies, log-log, ours and the peer's per family.
fn scaling_chart(area: &Area, peer: &str, rows: &[Row]) -> DrawResult {
    let bodies = rows.iter().map(|r| r.bodies.max(1) as f64);
    let ms = rows.iter().flat_map(|r| [Some(r.ours_ms), r.peer_ms]).flatten();
    let (x0, x1) = bodies.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    let (y0, y1) = ms.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    let mut chart = ChartBuilder::on(area)
        .caption("ms per step against bodies", ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d((x0 / 2.0..x1 * 2.0).log_scale(), (y0 / 2.0..y1 * 2.0).log_scale())?;
    chart.configure_mesh().x_desc("bodies").y_desc("ms per step").x_label_formatter(&|b| count(*b)).draw()?;
    let mut families: Vec<&str> = Vec::new();
    for r in rows {
        if !families.contains(&family(&r.case)) {
            families.push(family(&r.case));
        }
    }
    for (k, fam) in families.iter().enumerate() {
        let colour = FAMILY_COLOURS[k % FAMILY_COLOURS.len()];
        let members: Vec<&Row> = rows.iter().filter(|r| family(&r.case) == *fam).collect();
        let ours: Vec<(f64, f64)> = members.iter().map(|r| (r.bodies.max(1) as f64, r.ours_ms)).collect();
        chart
            .draw_series(LineSeries::new(ours.clone(), colour.stroke_width(2)))?
            .label(format!("verlet, {fam}"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
        chart.draw_series(ours.iter().map(|&p| Circle::new(p, 4, colour.filled())))?;
        let theirs: Vec<(f64, f64)> = members.iter().filter_map(|r| r.peer_ms.map(|ms| (r.bodies.max(1) as f64, ms))).collect();
        if !theirs.is_empty() {
            let faded = colour.mix(0.5);
            chart
                .draw_series(LineSeries::new(theirs.clone(), faded.stroke_width(2)))?
                .label(format!("{peer}, {fam}"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], faded.stroke_width(2)));
            chart.draw_series(theirs.iter().map(|&(x, y)| TriangleMarker::new((x, y), 5, faded.filled())))?;
        }
    }
    chart.configure_series_labels().position(SeriesLabelPosition::UpperLeft).border_style(BLACK).background_style(WHITE).draw()?;
    Ok(())
}

/// Each case's step split into its parts, as shares of the step (so cases
/// of any size compare), stacked; the row names the step's total.
fn parts_chart(area: &Area, rows: &[Row]) -> DrawResult {
    let split: Vec<(String, [f64; 5])> = rows
        .iter()
        .filter_map(|r| r.parts.map(|p| (r, p, p.iter().sum::<f64>())))
        .filter(|(_, _, total)| *total > 0.0)
        .map(|(r, p, total)| (format!("{} ({:.1} ms)", r.case, total), p.map(|x| 100.0 * x / total)))
        .collect();
    if split.is_empty() {
        area.draw_text("no per-stage times in this run (--profile-steps 0)", &("sans-serif", 14).into(), (40, 240))?;
        return Ok(());
    }
    let mut chart = ChartBuilder::on(area)
        .caption("where a step goes (share of the GPU time, %)", ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(130)
        // room on the right for the legend
        .build_cartesian_2d(0.0..135.0, 0.0..split.len() as f64)?;
    chart
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(split.len() * 2 + 1)
        .y_label_formatter(&|y| {
            let k = y.floor() as usize;
            if (y - k as f64 - 0.5).abs() < 0.01 {
                split.get(k).map(|s| s.0.clone()).unwrap_or_default()
            } else {
                String::new()
            }
        })
        .x_labels(8)
        .x_label_formatter(&|x| if *x <= 100.0 { format!("{x:.0}") } else { String::new() })
        .x_desc("% of the step")
        .draw()?;
    for (part, (name, colour)) in PARTS.iter().zip(PART_COLOURS).enumerate() {
        let bars = split.iter().enumerate().map(|(k, (_, p))| {
            let from: f64 = p[..part].iter().sum();
            Rectangle::new([(from, k as f64 + 0.2), (from + p[part], k as f64 + 0.8)], colour.filled())
        });
        chart.draw_series(bars)?.label(*name).legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], colour.filled()));
    }
    chart.configure_series_labels().position(SeriesLabelPosition::UpperRight).border_style(BLACK).background_style(WHITE).draw()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(case: &str, bodies: usize, ours: f64, peer: Option<f64>) -> Row {
        Row {
            case: case.into(),
            bodies,
            ours_ms: ours,
            peer_ms: peer,
            parts: Some([0.1 * ours, 0.4 * ours, 0.05 * ours, 0.3 * ours, 0.15 * ours]),
        }
    }

    #[test]
    fn families_drop_the_size_suffix() {
        assert_eq!(family("pile-10k"), "pile");
        assert_eq!(family("cubes-1m"), "cubes");
        assert_eq!(family("pile-100"), "pile");
        assert_eq!(family("pyramid"), "pyramid");
        assert_eq!(family("rain-storm"), "rain-storm");
    }

    #[test]
    fn the_chart_holds_both_engines_every_case_and_every_part() {
        let rows =
            [row("pile-1k", 1000, 15.0, Some(6.9)), row("pile-10k", 10_000, 114.6, Some(101.2)), row("pyramid", 210, 9.0, None)];
        let svg = svg("llvmpipe, 2 cores", "rapier3d", &rows).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..80.min(svg.len())]);
        for label in [
            "verlet, pile",
            "rapier3d, pile",
            "verlet, pyramid",
            "pile-1k (15.0 ms)",
            "pile-10k (114.6 ms)",
            "pyramid (9.0 ms)",
            "llvmpipe, 2 cores",
        ] {
            assert!(svg.contains(label), "no {label:?} in the chart");
        }
        for part in PARTS {
            assert!(svg.contains(part), "no {part:?} in the legend");
        }
        // the pyramid has no peer: no rapier line for its family
        assert!(!svg.contains("rapier3d, pyramid"));
        // a point per case for ours (circles), per peer case (triangles: polygons)
        assert_eq!(svg.matches("<circle").count(), 3);
    }

    #[test]
    fn body_counts_read_as_people_write_them() {
        assert_eq!(count(500.0), "500");
        assert_eq!(count(1000.0), "1k");
        assert_eq!(count(10_000.0), "10k");
        assert_eq!(count(1_500_000.0), "1.5M");
    }

    #[test]
    fn nothing_to_plot_is_an_error() {
        assert!(svg("t", "rapier3d", &[]).is_err());
    }
}
