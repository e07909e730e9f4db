//! Where a frame is seen from, worked out from the scene once: the camera
//! (the scene's, or one that frames its bodies), its projection, and the
//! frame's constants that follow from them (the sun's view for shadows,
//! fog and grid spacing). Maths only; `gpu.rs` uploads the result.

use glam::{Mat4, Quat, Vec3};

use super::bodies::{srgb_to_linear, BACKGROUND_SRGB};
use super::gpu::Globals;
use crate::scene::{Scene, Shape, DEFAULT_FOV_Y};

/// The shadow map covers the scene's starting bounding sphere times this,
/// so bodies that roll or swing a little out of it still cast shadows.
const SHADOW_REACH: f32 = 1.5;
/// Where the default camera looks from, relative to the scene's centre:
/// above, in front and a little to the right, so three faces of an
/// axis-aligned box show, each lit differently.
pub(crate) const DEFAULT_VIEW_DIRECTION: [f32; 3] = [0.6, 0.5, 1.0];
/// The default camera leaves this much room around the scene's bounding
/// sphere (a factor on the distance that just fits it).
const FRAMING_MARGIN: f32 = 1.05;
/// Towards the sun: high, from the left and in front. Seen from the default
/// camera (right and in front) the top, front and right faces of a box get
/// three distinct shades, and shadows fall back and right, into view.
const LIGHT_DIRECTION: [f32; 3] = [-0.4, 1.0, 0.7];

/// Where the renderer looks from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraView {
    /// Eye position (m).
    pub position: [f32; 3],
    /// The point at the centre of the image (m).
    pub target: [f32; 3],
    /// Up in the image: +Y, or +Z when looking straight along Y.
    pub up: [f32; 3],
    /// Vertical field of view (radians).
    pub fov_y: f32,
}

/// The scene's extent: the bodies' starting bounding box (each body as its
/// bounding sphere), stretched down to the ground when there is one, since
/// bodies above it fall onto it. A bounding sphere of that box frames it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Framing {
    centre: Vec3,
    /// Radius of the bounding sphere (m), at least 1 mm.
    radius: f32,
}

fn framing(scene: &Scene) -> Framing {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for b in &scene.bodies {
        let mut p = Vec3::from_array(b.position);
        // a hull's bounding radius is about its centre of mass, which may lie off its frame's origin
        if let Shape::Hull(h) = &b.shape {
            p += Quat::from_array(b.orientation).normalize() * h.hull().centroid.as_vec3();
        }
        let r = Vec3::splat(b.shape.bounding_radius());
        lo = lo.min(p - r);
        hi = hi.max(p + r);
    }
    if scene.bodies.is_empty() {
        // nothing to frame: a 2 m box on the ground (or the origin)
        let y = scene.ground.as_ref().map_or(0.0, |g| g.height);
        lo = Vec3::new(-1.0, y, -1.0);
        hi = Vec3::new(1.0, y + 2.0, 1.0);
    }
    if let Some(g) = &scene.ground {
        lo.y = lo.y.min(g.height);
        hi.y = hi.y.max(g.height);
    }
    Framing { centre: 0.5 * (lo + hi), radius: (0.5 * (hi - lo).length()).max(1e-3) }
}

/// Up in the image: +Y, or +Z when looking (nearly) straight along Y.
fn up_for(forward: Vec3) -> Vec3 {
    if forward.normalize_or_zero().y.abs() > 0.999 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// The scene's camera if it has one; else one looking at the centre of the
/// scene from `DEFAULT_VIEW_DIRECTION`, just far enough that the bounding
/// sphere fits both the vertical and the horizontal field of view.
pub(super) fn choose_camera(scene: &Scene, aspect: f32) -> (CameraView, Framing) {
    let f = framing(scene);
    let camera = match &scene.camera {
        Some(c) => {
            let forward = Vec3::from_array(c.target) - Vec3::from_array(c.position);
            CameraView { position: c.position, target: c.target, up: up_for(forward).to_array(), fov_y: c.fov_y }
        }
        None => {
            let fov_y = DEFAULT_FOV_Y;
            let fov_x = 2.0 * ((0.5 * fov_y).tan() * aspect).atan();
            // a sphere of radius R fits a cone of half angle a from R / sin(a) away
            let distance = f.radius / (0.5 * fov_y.min(fov_x)).sin() * FRAMING_MARGIN;
            let position = f.centre + Vec3::from_array(DEFAULT_VIEW_DIRECTION).normalize() * distance;
            CameraView {
                position: position.to_array(),
                target: f.centre.to_array(),
                up: up_for(f.centre - position).to_array(),
                fov_y: DEFAULT_FOV_Y,
            }
        }
    };
    (camera, f)
}

/// World to clip space: a right-handed view, and a perspective with the
/// far plane at infinity and depth reversed (near = 1). The near plane sits
/// at a thousandth of the distance to the target: close enough for any body
/// in front of the camera, and reversed float depth loses nothing by it.
pub(super) fn view_projection(camera: &CameraView, aspect: f32) -> Mat4 {
    let eye = Vec3::from_array(camera.position);
    let target = Vec3::from_array(camera.target);
    let view = Mat4::look_at_rh(eye, target, Vec3::from_array(camera.up));
    let near = (1e-3 * eye.distance(target)).max(1e-5);
    let proj = Mat4::perspective_infinite_reverse_rh(camera.fov_y, aspect, near);
    proj * view
}

/// Texels along each side of the shadow map, for an image of `width` x
/// `height`: the map covers about 1.5 times what the image does (see
/// `SHADOW_REACH`), so 1.5 times the image's larger side, rounded up to a
/// power of two, keeps about a texel per pixel. Clearing and filling a
/// bigger map is most of a frame's cost on a software rasteriser.
pub(super) fn shadow_map_size(width: u32, height: u32, max: u32) -> u32 {
    (3 * width.max(height) / 2).next_power_of_two().clamp(512, 4096).min(max)
}

pub(super) fn make_globals(camera: &CameraView, view_proj: Mat4, f: &Framing, ground: Option<f32>, shadow_size: u32) -> Globals {
    let eye = Vec3::from_array(camera.position);
    let r = f.radius;
    let to_scene = eye.distance(f.centre);
    // fog from just behind the scene to well beyond, so the plane's edge never shows
    let (fog_start, fog_end) = (to_scene + 2.0 * r, to_scene + 8.0 * r);
    // minor lines a power of ten apart, about a twentieth of the scene's width or more
    let minor = 10f32.powf((r / 2.0).log10().floor());
    let light = Vec3::from_array(LIGHT_DIRECTION).normalize();
    // the sun's view: an orthographic box around the scene, looking along the light
    let reach = SHADOW_REACH * r;
    let sun_up = up_for(-light);
    let light_view = Mat4::look_at_rh(f.centre + 2.0 * reach * light, f.centre, sun_up);
    let light_proj = Mat4::orthographic_rh(-reach, reach, -reach, reach, 0.0, 4.0 * reach);
    let texel = 2.0 * reach / shadow_size as f32;
    let bg = BACKGROUND_SRGB.map(srgb_to_linear);
    Globals {
        view_proj: view_proj.to_cols_array_2d(),
        light_view_proj: (light_proj * light_view).to_cols_array_2d(),
        eye: [eye.x, eye.y, eye.z, 1.0],
        light_dir: [light.x, light.y, light.z, 1.5 * texel],
        ground: match ground {
            Some(h) => [h, f.centre.x, f.centre.z, fog_end + to_scene],
            None => [0.0; 4],
        },
        grid: [minor, 10.0 * minor, fog_start, fog_end],
        background: [bg[0], bg[1], bg[2], 1.0],
    }
}
