//! Off-screen rendering: golden images compared with a tolerance, the
//! camera's projection against the pixels, sizes, and the image writers.
//!
//! GPU tests skip loudly without an adapter and fail when `CI` is set (see
//! `common`). `VERLET_UPDATE_GOLDEN=1` rewrites the golden images.

use std::path::{Path, PathBuf};
use std::time::Instant;

use image::{Rgba, RgbaImage};
use verlet::render::{self, RenderOptions, Renderer};
use verlet::scene::Camera;
use verlet::{scenes, Error, Scene};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

/// Golden images pass when the mean absolute difference per channel is at
/// most this (of 255): a few edge pixels antialiased differently by another
/// driver, not a moved or recoloured body.
const MEAN_TOLERANCE: f64 = 2.0;
/// A pixel "differs" when one of its channels is off by more than this...
const PIXEL_THRESHOLD: u8 = 40;
/// ...and at most this share of pixels may differ (1%: a body shifted by
/// a pixel along its outline, not one gone or moved).
const SHARE_TOLERANCE: f64 = 0.01;

fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

struct Difference {
    mean_abs: f64,
    share_over: f64,
    image: RgbaImage,
}

/// Per-channel absolute differences (RGB), and an image of them, amplified.
fn difference(a: &RgbaImage, b: &RgbaImage) -> Difference {
    assert_eq!(a.dimensions(), b.dimensions());
    let mut sum = 0u64;
    let mut over = 0u64;
    let mut image = RgbaImage::new(a.width(), a.height());
    for ((pa, pb), pd) in a.pixels().zip(b.pixels()).zip(image.pixels_mut()) {
        let d = [0, 1, 2].map(|c| pa[c].abs_diff(pb[c]));
        sum += d.iter().map(|&v| v as u64).sum::<u64>();
        over += d.iter().any(|&v| v > PIXEL_THRESHOLD) as u64;
        *pd = Rgba([d[0].saturating_mul(4), d[1].saturating_mul(4), d[2].saturating_mul(4), 255]);
    }
    let pixels = (a.width() * a.height()) as f64;
    Difference { mean_abs: sum as f64 / (3.0 * pixels), share_over: over as f64 / pixels, image }
}

/// Compares `actual` with `tests/golden/<name>.png`; on a failure writes
/// `<name>.actual.png` and `<name>.diff.png` beside it. A missing golden
/// (or VERLET_UPDATE_GOLDEN=1) is written and the test passes, except under
/// CI, where a missing golden fails.
fn check_golden(name: &str, actual: &RgbaImage) {
    let dir = golden_dir();
    let expected_path = dir.join(format!("{name}.png"));
    let update = std::env::var("VERLET_UPDATE_GOLDEN").is_ok_and(|v| v == "1");
    if !update && !expected_path.exists() && std::env::var_os("CI").is_some() {
        panic!("golden {name}: {} is missing (under CI a missing golden fails)", expected_path.display());
    }
    if update || !expected_path.exists() {
        std::fs::create_dir_all(&dir).unwrap();
        render::write_png(actual, &expected_path).unwrap();
        let why = if update { "VERLET_UPDATE_GOLDEN=1" } else { "it was missing" };
        eprintln!("golden {name}: wrote {} ({why}); check it by eye and commit it", expected_path.display());
        return;
    }
    let expected = image::open(&expected_path).unwrap_or_else(|e| panic!("{}: {e}", expected_path.display())).to_rgba8();
    let actual_path = dir.join(format!("{name}.actual.png"));
    if expected.dimensions() != actual.dimensions() {
        render::write_png(actual, &actual_path).unwrap();
        panic!(
            "golden {name}: expected {:?}, rendered {:?}; see {}",
            expected.dimensions(),
            actual.dimensions(),
            actual_path.display()
        );
    }
    let d = difference(&expected, actual);
    if d.mean_abs > MEAN_TOLERANCE || d.share_over > SHARE_TOLERANCE {
        let diff_path = dir.join(format!("{name}.diff.png"));
        render::write_png(actual, &actual_path).unwrap();
        render::write_png(&d.image, &diff_path).unwrap();
        panic!(
            "golden {name}: mean abs difference {:.3}/255 (max {MEAN_TOLERANCE}), {:.2}% of pixels off by more than \
             {PIXEL_THRESHOLD} (max {:.2}%); see {} and {}",
            d.mean_abs,
            100.0 * d.share_over,
            100.0 * SHARE_TOLERANCE,
            actual_path.display(),
            diff_path.display()
        );
    }
    eprintln!("golden {name}: mean abs {:.3}/255, {:.3}% of pixels over {PIXEL_THRESHOLD}", d.mean_abs, 100.0 * d.share_over);
}

/// Renders `scene` after `steps` steps, or None when the test must skip.
fn render_after(scene: &Scene, steps: u64, options: RenderOptions) -> Option<RgbaImage> {
    let mut world = crate::common::world(scene)?;
    let mut renderer = Renderer::with_options(world.gpu(), scene, WIDTH, HEIGHT, options).unwrap();
    world.step(steps).unwrap();
    Some(renderer.render(&world).unwrap())
}

#[test]
fn golden_box_at_rest() {
    // placed at rest rather than dropped: the image tests the renderer, and
    // stays put when the physics is tuned
    let mut scene = scenes::stack(1);
    let half = 25f32.to_radians() / 2.0;
    scene.bodies[0].orientation = [0.0, half.sin(), 0.0, half.cos()];
    let Some(img) = render_after(&scene, 0, RenderOptions::default()) else { return };
    assert_eq!(img.dimensions(), (WIDTH, HEIGHT));
    check_golden("box_at_rest", &img);
}

#[test]
fn golden_stack() {
    let Some(img) = render_after(&scenes::stack(5), 0, RenderOptions::default()) else { return };
    assert_eq!(img.dimensions(), (WIDTH, HEIGHT));
    check_golden("stack", &img);
}

#[test]
fn golden_chain() {
    // unstepped: the chain as laid out, with its joint lines
    let Some(img) = render_after(&scenes::chain(21), 0, RenderOptions { draw_joints: true }) else { return };
    assert_eq!(img.dimensions(), (WIDTH, HEIGHT));
    check_golden("chain", &img);
}

/// Pure red, shaded: red well above green and blue.
fn is_red(p: &Rgba<u8>) -> bool {
    p[0] > 40 && p[0] as u32 > 2 * p[1] as u32 + 10 && p[0] as u32 > 2 * p[2] as u32 + 10
}

/// Centroid of the pixels `keep` picks, and how many.
fn centroid(img: &RgbaImage, keep: impl Fn(&Rgba<u8>) -> bool) -> ([f64; 2], usize) {
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0usize);
    for (x, y, p) in img.enumerate_pixels() {
        if keep(p) {
            sx += x as f64 + 0.5;
            sy += y as f64 + 0.5;
            n += 1;
        }
    }
    ([sx / n.max(1) as f64, sy / n.max(1) as f64], n)
}

#[test]
fn silhouette_lands_where_the_camera_projects_it() {
    let position = [1.5, 0.6, -0.8];
    let mut scene = scenes::drop();
    scene.bodies[0] = scenes::box_body([0.4, 0.4, 0.4], position);
    // a camera far enough that perspective barely shifts the silhouette's
    // centroid from the centre's image, aimed away from the box so it sits
    // off the image's centre
    scene.camera = Some(Camera { position: [6.0, 7.0, 14.0], target: [0.0, 0.5, 0.0], fov_y: 30f32.to_radians() });
    let Some(world) = crate::common::world(&scene) else { return };
    let mut renderer = Renderer::new(world.gpu(), &scene, WIDTH, HEIGHT).unwrap();
    renderer.set_body_color(0, [1.0, 0.0, 0.0]).unwrap();
    let img = renderer.render(&world).unwrap();
    let centre = renderer.project([0.0, 0.5, 0.0]).unwrap();
    assert!((centre[0] - WIDTH as f32 / 2.0).abs() < 0.01 && (centre[1] - HEIGHT as f32 / 2.0).abs() < 0.01);
    let expected = renderer.project(position).expect("the box is in view");
    let ([cx, cy], n) = centroid(&img, is_red);
    assert!(n > 100, "only {n} red pixels");
    let off = ((cx - expected[0] as f64).powi(2) + (cy - expected[1] as f64).powi(2)).sqrt();
    eprintln!("{n} red pixels, centroid ({cx:.2}, {cy:.2}), projected centre {expected:?}, {off:.2} px apart");
    assert!(off < 2.0, "silhouette centroid ({cx:.1}, {cy:.1}) is {off:.1} px from the projected centre {expected:?}");
    // and the box is well off the image's centre, so this means something
    assert!((expected[0] - centre[0]).abs() > 30.0);
    // nothing red elsewhere: the ground and background are not mistaken for the body
    let far = renderer.project([-1.5, 0.0, 1.0]).unwrap();
    assert!(!is_red(img.get_pixel(far[0] as u32, far[1] as u32)));
}

#[test]
fn default_camera_frames_every_body() {
    let scene = scenes::chain(21);
    let Some(world) = crate::common::world(&scene) else { return };
    let renderer = Renderer::new(world.gpu(), &scene, WIDTH, HEIGHT).unwrap();
    let cam = renderer.camera();
    assert_eq!(cam.fov_y, std::f32::consts::FRAC_PI_4);
    assert_eq!(cam.up, [0.0, 1.0, 0.0]);
    for b in &scene.bodies {
        let r = b.shape.bounding_radius();
        for dx in [-r, r] {
            for dy in [-r, r] {
                let p = [b.position[0] + dx, b.position[1] + dy, b.position[2]];
                assert!(renderer.project(p).is_some(), "{p:?} is out of the frame");
            }
        }
    }
    // the hanging chain, after it swings down, and the ground below the pin
    assert!(renderer.project([0.0, 2.0, 0.0]).is_some());
    assert!(renderer.project([0.0, 0.0, 0.0]).is_some());
}

#[test]
fn looking_straight_down_turns_up_to_z() {
    let mut scene = scenes::drop();
    scene.camera = Some(Camera { position: [0.0, 10.0, 0.0], target: [0.0, 0.0, 0.0], fov_y: 60f32.to_radians() });
    let Some(world) = crate::common::world(&scene) else { return };
    let mut renderer = Renderer::new(world.gpu(), &scene, 64, 48).unwrap();
    assert_eq!(renderer.camera().up, [0.0, 0.0, 1.0]);
    let img = renderer.render(&world).unwrap();
    assert_eq!(img.dimensions(), (64, 48));
}

#[test]
fn frames_of_a_moving_scene_differ() {
    let scene = scenes::drop();
    let Some(mut world) = crate::common::world(&scene) else { return };
    let mut renderer = Renderer::new(world.gpu(), &scene, WIDTH, HEIGHT).unwrap();
    let before = renderer.render(&world).unwrap();
    let again = renderer.render(&world).unwrap();
    assert_eq!(before, again, "the same state renders the same image");
    world.step(30).unwrap();
    let after = renderer.render(&world).unwrap();
    let d = difference(&before, &after);
    // and by more than a golden image's tolerance: the golden checks would catch a moved body
    assert!(d.share_over > SHARE_TOLERANCE, "only {:.3}% of pixels changed as the box fell", 100.0 * d.share_over);
}

#[test]
fn an_odd_size_renders_unskewed() {
    let (w, h) = (333, 211);
    let scene = scenes::stack(3);
    let Some(world) = crate::common::world(&scene) else { return };
    let mut renderer = Renderer::new(world.gpu(), &scene, w, h).unwrap();
    renderer.set_body_color(0, [0.2, 0.4, 1.0]).unwrap();
    renderer.set_body_color(1, [0.2, 0.4, 1.0]).unwrap();
    renderer.set_body_color(2, [1.0, 0.0, 0.0]).unwrap();
    let img = renderer.render(&world).unwrap();
    assert_eq!(img.dimensions(), (w, h));
    // row padding dropped correctly: the top box is where the camera puts it
    let expected = renderer.project(scene.bodies[2].position).unwrap();
    let ([cx, cy], n) = centroid(&img, is_red);
    assert!(n > 50, "only {n} red pixels");
    let off = ((cx - expected[0] as f64).powi(2) + (cy - expected[1] as f64).powi(2)).sqrt();
    assert!(off < 3.0, "top box's centroid ({cx:.1}, {cy:.1}) is {off:.1} px from {expected:?}");
}

#[test]
fn bad_sizes_are_refused_naming_the_argument() {
    let Some(gpu) = crate::common::gpu() else { return };
    let scene = scenes::drop();
    let max = gpu.limits.max_texture_dimension_2d;
    for (w, h, arg) in [(0, 240, "width"), (320, 0, "height"), (max + 1, 240, "width"), (320, max + 1, "height")] {
        match Renderer::new(&gpu, &scene, w, h) {
            Err(Error::Argument { name, reason }) => assert_eq!(name, arg, "{w}x{h}: {reason}"),
            Err(e) => panic!("{w}x{h}: wrong error {e}"),
            Ok(_) => panic!("{w}x{h} accepted"),
        }
    }
}

#[test]
fn a_world_of_another_scene_is_refused() {
    let Some(world) = crate::common::world(&scenes::stack(3)) else { return };
    let mut renderer = Renderer::new(world.gpu(), &scenes::stack(4), 32, 32).unwrap();
    assert!(matches!(renderer.render(&world), Err(Error::Input(_))));
}

#[test]
fn spheres_and_fixed_bodies_render() {
    let mut scene = scenes::sphere();
    let mut post = scenes::box_body([0.3, 1.0, 0.3], [1.2, 1.0, 0.0]);
    post.fixed = true;
    scene.bodies.push(post);
    let Some(world) = crate::common::world(&scene) else { return };
    let mut renderer = Renderer::new(world.gpu(), &scene, 160, 120).unwrap();
    let img = renderer.render(&world).unwrap();
    // the fixed post is grey: its centre pixel has r = g = b within rounding
    let p = renderer.project([1.2, 1.0, 0.3]).unwrap();
    let px = img.get_pixel(p[0] as u32, p[1] as u32);
    assert!(px[0].abs_diff(px[1]) <= 8 && px[1].abs_diff(px[2]) <= 8, "fixed body not grey: {px:?}");
    // the sphere is drawn: its centre is coloured (body 0: red)
    let s = renderer.project(scene.bodies[0].position).unwrap();
    assert!(is_red(img.get_pixel(s[0] as u32, s[1] as u32)) || img.get_pixel(s[0] as u32, s[1] as u32)[0] > 200);
}

/// A capsule lying along x is drawn as one: its colour under its segment's
/// ends and middle and within its caps, not just beyond them.
#[test]
fn a_capsule_renders_as_a_capsule() {
    let (r, h) = (0.3f32, 1.0f32);
    let mut scene = scenes::drop();
    let mut capsule = verlet::Body::new(verlet::Shape::Capsule { radius: r, half_height: h }, [0.0, 1.0, 0.0]);
    capsule.orientation = glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2).to_array();
    scene.bodies = vec![capsule];
    scene.camera = Some(Camera { position: [0.0, 1.0, 12.0], target: [0.0, 1.0, 0.0], fov_y: 30f32.to_radians() });
    let Some(world) = crate::common::world(&scene) else { return };
    let mut renderer = Renderer::new(world.gpu(), &scene, WIDTH, HEIGHT).unwrap();
    renderer.set_body_color(0, [1.0, 0.0, 0.0]).unwrap();
    let img = renderer.render(&world).unwrap();
    // red, or its lighter tone (the octants of a round body alternate)
    let red_at = |x: f32, y: f32| {
        let p = renderer.project([x, y, 0.0]).unwrap();
        let px = img.get_pixel(p[0] as u32, p[1] as u32);
        px[0] as i32 > px[2] as i32 + 40
    };
    for x in [-h, -0.5 * h, 0.0, 0.5 * h, h, h + 0.8 * r, -h - 0.8 * r] {
        assert!(red_at(x, 1.0), "no capsule at x = {x}");
    }
    for (x, y) in [(h + 1.3 * r, 1.0), (-h - 1.3 * r, 1.0), (0.0, 1.0 + 1.3 * r), (h + 0.8 * r, 1.0 + 0.8 * r)] {
        assert!(!red_at(x, y), "capsule drawn at ({x}, {y}), outside it");
    }
}

/// Pure blue, shaded: blue well above red and green.
fn is_blue(p: &Rgba<u8>) -> bool {
    p[2] > 40 && p[2] as u32 > 2 * p[0] as u32 + 10 && p[2] as u32 > 2 * p[1] as u32 + 10
}

/// Hulls are drawn as their faces, where their points are: a prism over a
/// scalene triangle, seen end on, turned about the view axis, its points
/// well off its frame's origin. One is fixed (its pose kept at its centre
/// of mass on its principal axes, `Body::mass_frame`), one kinematic (its
/// pose kept in its own frame): each covers its own triangle and not the
/// disc of its bounding sphere.
#[test]
fn hulls_render_as_their_faces_where_their_points_are() {
    use glam::{Quat, Vec2, Vec3};
    let triangle = [Vec2::new(0.0, 0.0), Vec2::new(2.0, 0.0), Vec2::new(0.4, 1.5)];
    let (offset, depth) = (Vec2::new(1.5, -0.4), 0.3f32);
    let points: Vec<[f32; 3]> = [-depth, depth].iter().flat_map(|&z| triangle.map(|t| (t + offset).extend(z).to_array())).collect();
    let shape = verlet::scene::HullShape::new(points).unwrap();
    let hull = |position: [f32; 3], turn: f32, kinematic: bool| {
        let mut b = verlet::Body::new(verlet::Shape::Hull(shape.clone()), position);
        b.orientation = Quat::from_rotation_z(turn).to_array();
        (b.fixed, b.kinematic) = (!kinematic, kinematic);
        b
    };
    let mut scene = scenes::drop();
    scene.bodies = vec![hull([-4.0, 0.5, 0.0], 0.35, false), hull([0.2, 1.7, 0.0], -0.25, true)];
    assert!(scene.bodies[0].mass_frame().is_some() && scene.bodies[1].mass_frame().is_none());
    scene.camera = Some(Camera { position: [0.0, 1.0, 12.0], target: [0.0, 1.0, 0.0], fov_y: 30f32.to_radians() });
    let Some(world) = crate::common::world(&scene) else { return };
    let mut renderer = Renderer::new(world.gpu(), &scene, WIDTH, HEIGHT).unwrap();
    renderer.set_body_color(0, [1.0, 0.0, 0.0]).unwrap();
    renderer.set_body_color(1, [0.0, 0.0, 1.0]).unwrap();
    let img = renderer.render(&world).unwrap();

    let colours: [fn(&Rgba<u8>) -> bool; 2] = [is_red, is_blue];
    for (k, (body, is_colour)) in scene.bodies.iter().zip(colours).enumerate() {
        // a point of the body's frame in the world, and in the image
        let world_point = |p: Vec3| Vec3::from_array(body.position) + Quat::from_array(body.orientation) * p;
        let pixel = |p: Vec3| renderer.project(world_point(p).to_array()).expect("the hull is in view");
        let coloured = |p: Vec3| {
            let q = pixel(p);
            is_colour(img.get_pixel(q[0] as u32, q[1] as u32))
        };
        // on the face towards the camera
        let front = |t: Vec2| (t + offset).extend(depth);
        let g = (triangle[0] + triangle[1] + triangle[2]) / 3.0;
        for t in triangle {
            assert!(coloured(front(g + 0.8 * (t - g))), "body {k}: not drawn towards corner {t}");
        }
        assert!(coloured(front(g)), "body {k}: not drawn at its middle");
        // beyond each edge by a fifth of its height or more, inside the bounding sphere
        let radius = body.bounding_radius();
        let centre = shape.hull().centroid.as_vec3();
        for e in 0..3 {
            let mid = 0.5 * (triangle[e] + triangle[(e + 1) % 3]);
            let t = g + 1.6 * (mid - g);
            assert!((front(t) - centre).length() < 0.9 * radius);
            assert!(!coloured(front(t)), "body {k}: drawn beyond edge {e}, inside its bounding sphere");
        }
        // the pixels it covers: about its triangle's, far fewer than its bounding sphere's
        let corners = triangle.map(|t| Vec2::from_array(pixel(front(t))));
        let triangle_px = 0.5 * (corners[1] - corners[0]).perp_dot(corners[2] - corners[0]).abs();
        let disc_px = std::f32::consts::PI
            * (Vec2::from_array(pixel(centre)) - Vec2::from_array(pixel(centre + radius * Vec3::X))).length_squared();
        let (_, n) = centroid(&img, is_colour);
        eprintln!("body {k}: {n} pixels, its front triangle {triangle_px:.0}, its bounding sphere's disc {disc_px:.0}");
        assert!((0.9..1.2).contains(&(n as f32 / triangle_px)), "body {k}: {n} pixels for a triangle of {triangle_px:.0}");
        assert!((n as f32) < 0.4 * disc_px, "body {k}: {n} pixels, near its bounding sphere's {disc_px:.0}");
    }
}

#[test]
fn the_render_shader_validates_with_naga() {
    let module = verlet::gpu::shaders::validate(&render::shader_source()).unwrap_or_else(|e| panic!("render.wgsl:\n{e}"));
    for name in ["body_vertex", "body_fragment", "ground_vertex", "ground_fragment", "joint_vertex", "joint_fragment"] {
        assert!(module.entry_points.iter().any(|e| e.name == name), "no entry point {name}");
    }
}

/// (member name, offset) of a WGSL struct, and its size.
fn wgsl_layout(source: &str, name: &str) -> (Vec<(String, u32)>, u32) {
    let module = verlet::gpu::shaders::validate(source).expect("validates");
    for (_, ty) in module.types.iter() {
        if ty.name.as_deref() == Some(name) {
            if let naga::TypeInner::Struct { members, span } = &ty.inner {
                return (members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect(), *span);
            }
        }
    }
    panic!("struct {name} not found");
}

macro_rules! check_layout {
    ($ty:path, $name:literal { $($field:ident),* $(,)? }) => {{
        let rust: Vec<(String, u32)> = vec![$((stringify!($field).to_string(), std::mem::offset_of!($ty, $field) as u32)),*];
        let (wgsl, span) = wgsl_layout(&render::shader_source(), $name);
        assert_eq!(wgsl, rust, "{}: members differ between render.wgsl and Rust", $name);
        assert_eq!(span as usize, std::mem::size_of::<$ty>(), "{}: size differs", $name);
    }};
}

#[test]
fn render_structs_match_the_wgsl() {
    check_layout!(render::Globals, "Globals" { view_proj, light_view_proj, eye, light_dir, ground, grid, background });
    check_layout!(render::RenderBody, "RenderBody" { half_extents, body, color, shape });
    check_layout!(render::JointLine, "JointLine" { anchor_a, body_a, anchor_b, body_b });
    // the renderer reads the step's pose (common.wgsl's BodyState)
    check_layout!(verlet::gpu::types::BodyState, "BodyState" { pos, rest_time, disp, pos_low, rot, prev_rot });
}

#[test]
fn contact_sheet_tiles_and_gif_writes() {
    let frames: Vec<RgbaImage> = (0..3u8).map(|k| RgbaImage::from_pixel(40, 30, Rgba([80 * k, 0, 0, 255]))).collect();
    let sheet = render::contact_sheet(&frames, 2, None).unwrap();
    assert_eq!(sheet.dimensions(), (2 * 40 + 3 * 2, 2 * 30 + 3 * 2));
    assert_eq!(*sheet.get_pixel(2 + 40 + 2 + 5, 2 + 5), Rgba([80, 0, 0, 255]));
    assert_eq!(*sheet.get_pixel(2 + 5, 2 + 30 + 2 + 5), Rgba([160, 0, 0, 255]));
    let small = render::contact_sheet(&frames, 3, Some(20)).unwrap();
    assert_eq!(small.dimensions(), (3 * 20 + 4 * 2, 15 + 2 * 2));
    assert!(render::contact_sheet(&[], 2, None).is_err());

    let dir = std::env::temp_dir().join(format!("verlet-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let gif = dir.join("anim.gif");
    render::write_gif(&frames, 100.0, &gif).unwrap();
    let bytes = std::fs::read(&gif).unwrap();
    assert!(bytes.starts_with(b"GIF89a"));
    let png = dir.join("sheet.png");
    render::write_png(&sheet, &png).unwrap();
    assert_eq!(image::open(&png).unwrap().to_rgba8(), sheet);
    let odd = vec![frames[0].clone(), RgbaImage::new(10, 10)];
    assert!(matches!(render::write_gif(&odd, 100.0, &dir.join("bad.gif")), Err(Error::Input(_))));
    assert!(matches!(render::write_png(&sheet, &dir.join("no/such/dir.png")), Err(Error::Io { .. })));
    std::fs::remove_dir_all(&dir).unwrap();
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// `cargo test --test gpu -- --ignored --nocapture render::timing`: one 640x480
/// frame of 1000 cubes against one step, wall clock, median of a few.
#[test]
#[ignore]
fn timing_render_vs_step_1000_cubes() {
    let scene = scenes::cubes(1000, 1);
    let Some(mut world) = crate::common::world(&scene) else { return };
    let mut renderer = Renderer::new(world.gpu(), &scene, 640, 480).unwrap();
    world.step(1).unwrap();
    world.gpu().wait().unwrap();
    renderer.render(&world).unwrap(); // warm-up: first use of each pipeline
    let (mut render_ms, mut step_ms) = (Vec::new(), Vec::new());
    for _ in 0..7 {
        let t = Instant::now();
        world.step(1).unwrap();
        world.gpu().wait().unwrap();
        step_ms.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        let img = renderer.render(&world).unwrap();
        render_ms.push(t.elapsed().as_secs_f64() * 1e3);
        assert_eq!(img.dimensions(), (640, 480));
    }
    let (r, s) = (median(render_ms.clone()), median(step_ms.clone()));
    println!("adapter: {}", world.gpu().describe());
    println!("render 640x480, 1000 cubes: median {r:.1} ms  {render_ms:.1?}");
    println!("step(1), 1000 cubes:        median {s:.1} ms  {step_ms:.1?}");
    println!("render / step = {:.2}", r / s);
}
