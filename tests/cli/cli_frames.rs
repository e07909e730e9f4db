//! `verlet run --frames`: the binary writes the frames INTERFACE.md section 3
//! promises, and refuses bad image flags cleanly.

use crate::common::{no_adapter, temp_path as temp_dir, verlet};

#[test]
fn frames_are_written_every_k_steps_at_the_asked_size() {
    let dir = temp_dir("drop");
    let out = verlet(&[
        "run",
        "--builtin",
        "drop",
        "--steps",
        "20",
        "--every",
        "10",
        "--frames",
        dir.to_str().unwrap(),
        "--width",
        "333",
        "--height",
        "211",
    ]);
    if no_adapter(&out) {
        return;
    }
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "verlet run failed: {stderr}");

    // steps 0, 10 and 20: exactly three frames, numbered in sequence
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("the frames directory exists")
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["frame_000000.png", "frame_000001.png", "frame_000002.png"]);

    let frames: Vec<image::RgbaImage> =
        names.iter().map(|n| image::open(dir.join(n)).expect("a readable PNG").to_rgba8()).collect();
    for (name, f) in names.iter().zip(&frames) {
        assert_eq!(f.dimensions(), (333, 211), "{name}");
    }
    // the box falls: each frame shows it somewhere else
    for k in 1..frames.len() {
        assert_ne!(frames[k - 1].as_raw(), frames[k].as_raw(), "{} and {} are identical", names[k - 1], names[k]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn gif_and_contact_sheet_without_frames() {
    let dir = temp_dir("gif");
    std::fs::create_dir_all(&dir).unwrap();
    let (gif, sheet) = (dir.join("run.gif"), dir.join("sheet.png"));
    let out = verlet(&[
        "run",
        "--builtin",
        "drop",
        "--steps",
        "30",
        "--every",
        "10",
        "--gif",
        gif.to_str().unwrap(),
        "--contact-sheet",
        sheet.to_str().unwrap(),
        "--width",
        "160",
        "--height",
        "120",
    ]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "verlet run failed: {}", String::from_utf8_lossy(&out.stderr));
    let decoder =
        image::codecs::gif::GifDecoder::new(std::io::BufReader::new(std::fs::File::open(&gif).unwrap())).expect("a readable GIF");
    let frames = image::AnimationDecoder::into_frames(decoder).collect_frames().expect("GIF frames decode");
    assert_eq!(frames.len(), 4, "steps 0, 10, 20, 30");
    assert_eq!(frames[0].buffer().dimensions(), (160, 120));
    // 4 tiles: 2 x 2 with 2-pixel gutters
    let sheet = image::open(&sheet).expect("a readable PNG");
    assert_eq!((sheet.width(), sheet.height()), (2 * 160 + 3 * 2, 2 * 120 + 3 * 2));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A GIF plays in real time: frames recorded closer than the 20 ms that
/// viewers keep are thinned, not shown slower. 1 s at 60 Hz played in 1.22
/// s (61 frames of 20 ms), and 0.06 s at dt 1 ms in 1.22 s too.
#[test]
fn a_gif_plays_in_real_time() {
    let dir = temp_dir("gif-time");
    std::fs::create_dir_all(&dir).unwrap();
    let gif = dir.join("run.gif");
    for (steps, dt, simulated) in [("60", "0.016666668", 1.0), ("60", "0.001", 0.06)] {
        let args = [
            "run",
            "--builtin",
            "drop",
            "--steps",
            steps,
            "--dt",
            dt,
            "--gif",
            gif.to_str().unwrap(),
            "--width",
            "32",
            "--height",
            "24",
        ];
        let out = verlet(&args);
        if no_adapter(&out) {
            return;
        }
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let decoder = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(std::fs::File::open(&gif).unwrap())).unwrap();
        let frames = image::AnimationDecoder::into_frames(decoder).collect_frames().unwrap();
        let delays: Vec<f64> = frames
            .iter()
            .map(|f| {
                let (n, d) = f.delay().numer_denom_ms();
                n as f64 / d as f64
            })
            .collect();
        // the frames before the last span the run (the last one is shown as long)
        let span: f64 = delays[..delays.len() - 1].iter().sum::<f64>() / 1e3;
        assert!(delays.iter().all(|&d| d >= 20.0), "{dt}: delays {delays:?}");
        assert!(
            (span - simulated).abs() <= 0.02 + 0.02 * simulated,
            "{dt}: {} frames span {span} s of a {simulated} s run",
            frames.len()
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_image_flags_are_refused_naming_the_flag() {
    let dir = temp_dir("refused");
    let dir_arg = dir.to_str().unwrap();
    for (flag, args) in [
        ("--width", vec!["--width", "0"]),
        ("--height", vec!["--height", "0"]),
        ("--width", vec!["--width=-5"]),
        ("--every", vec!["--every", "0"]),
    ] {
        let mut all = vec!["run", "--builtin", "drop", "--steps", "5", "--frames", dir_arg];
        all.extend(args.iter().copied());
        let out = verlet(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}: exit status 0");
        assert!(!stderr.contains("panicked"), "{args:?}: panicked: {stderr}");
        assert!(stderr.contains(flag), "{args:?}: expected {flag} in {stderr:?}");
        assert_eq!(stderr.trim().lines().count(), 1, "{args:?}: not one line: {stderr:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_unwritable_frames_directory_is_refused_naming_the_flag() {
    // a directory cannot be made inside a regular file
    let file = temp_dir("file");
    std::fs::write(&file, b"not a directory").unwrap();
    let inside = file.join("frames");
    let out = verlet(&["run", "--builtin", "drop", "--steps", "5", "--frames", inside.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains("--frames") && stderr.contains(inside.to_str().unwrap()), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "not one line: {stderr:?}");
    let _ = std::fs::remove_file(&file);
}

#[test]
fn a_frames_directory_that_takes_no_files_is_refused_before_the_first_step() {
    // /proc/self is a directory in which no file can be made
    let out = verlet(&["run", "--builtin", "drop", "--steps", "2", "--frames", "/proc/self", "--width", "8", "--height", "8"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(!stderr.contains("panicked") && !stderr.contains("note:"), "refused after the run began: {stderr}");
    assert!(stderr.contains("--frames") && stderr.contains("/proc/self") && stderr.contains("cannot create files"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "not one line: {stderr:?}");
}

#[test]
fn a_run_that_wrote_no_frame_says_so() {
    // a directory where frame 0 goes: the directory takes files, but the
    // frame cannot be put there, so the run fails at step 0
    let dir = temp_dir("no-frame");
    std::fs::create_dir_all(dir.join("frame_000000.png").join("inside")).unwrap();
    let out =
        verlet(&["run", "--builtin", "drop", "--steps", "2", "--frames", dir.to_str().unwrap(), "--width", "8", "--height", "8"]);
    if no_adapter(&out) {
        return;
    }
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains(&format!("note: --frames: no frame was written to {}", dir.display())), "{stderr}");
    assert!(!stderr.contains("no step"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn outputs_inside_the_frames_directory_it_makes_are_taken() {
    let base = temp_dir("made");
    std::fs::create_dir_all(&base).unwrap();
    let d = |name: &str| base.join(name).to_str().unwrap().to_string();
    let run = |extra: &[&str]| {
        let mut args = vec!["run", "--builtin", "drop", "--steps", "2", "--width", "8", "--height", "8"];
        args.extend(extra);
        verlet(&args)
    };
    // refused for another reason: nothing is made, not even the frames directory
    for (extra, wanted) in [
        (vec!["--frames", &d("a"), "--gif", &d("a/run.gif"), "--width", "100000"], "--width"),
        (vec!["--frames", &d("b"), "--gif", &d("b/sub/run.gif")], "no directory"),
        (vec!["--frames", &d("c"), "--gif", &d("c/frame_000001.png")], "--frames"),
    ] {
        let out = run(&extra);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{extra:?}: exit status 0");
        assert!(stderr.contains(wanted) && !stderr.contains("panicked"), "{extra:?}: {stderr}");
        assert_eq!(std::fs::read_dir(&base).unwrap().count(), 0, "{extra:?}: something was made");
    }
    let (dir, gif, sheet) = (d("new"), d("new/run.gif"), d("new/sheet.png"));
    let (state, trace) = (d("new/./state.json"), d("new/trace.csv"));
    let out = run(&["--frames", &dir, "--gif", &gif, "--contact-sheet", &sheet, "--state-out", &state, "--trace", &trace]);
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(
        names,
        ["frame_000000.png", "frame_000001.png", "frame_000002.png", "run.gif", "sheet.png", "state.json", "trace.csv"]
    );
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn frames_of_an_earlier_longer_run_are_warned_of() {
    let dir = temp_dir("stale");
    let d = dir.to_str().unwrap();
    let run = |steps: &str| verlet(&["run", "--builtin", "drop", "--steps", steps, "--frames", d, "--width", "8", "--height", "8"]);
    let out = run("5");
    if no_adapter(&out) {
        return;
    }
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!String::from_utf8_lossy(&out.stderr).contains("warning"), "{}", String::from_utf8_lossy(&out.stderr));
    // a frame-named file this run would never write counts too
    std::fs::write(dir.join("frame_0000001.png"), b"not ours").unwrap();
    // two frames now: frame_000002.png to frame_000005.png stay from the first run
    let out = run("1");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let warning = stderr.lines().find(|l| l.starts_with("warning: --frames")).unwrap_or_else(|| panic!("no warning: {stderr}"));
    for wanted in [d, "5 frame files", "frame_0000001.png", "frame_000005.png"] {
        assert!(warning.contains(wanted), "{wanted:?} not in {warning:?}");
    }
    // the frames are where they were: the warning changes nothing
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 7);
    // a run as long as the first replaces all of its frames: no warning
    std::fs::remove_file(dir.join("frame_0000001.png")).unwrap();
    let out = run("5");
    assert!(out.status.success());
    assert!(!String::from_utf8_lossy(&out.stderr).contains("warning"), "{}", String::from_utf8_lossy(&out.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}
