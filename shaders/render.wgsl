// Off-screen rendering of a world (host code: src/render/mod.rs). The bodies are
// drawn straight from the world's current state buffer, bound read-only: one
// instance per body, a unit mesh (cube or icosphere) scaled, or a hull's own
// mesh, turned and moved to its centre in the vertex shader, so nothing is
// read back to draw.
//
// Two passes, four pipelines, all reading bind group 0:
//   shadow_vertex                    the bodies' depth as the sun sees them
//   body_vertex / body_fragment      the bodies, lit (sun, shadows, sky ambient)
//   ground_vertex / ground_fragment  the plane y = height, with a grid
//   joint_vertex / joint_fragment    optional joint lines, drawn on top
// Group 1 (the shadow map) is bound in the second pass only. Depth is reversed
// (near = 1, far = 0, infinite far plane), so a 32-bit float depth buffer
// keeps its precision from the near plane to the horizon.

// BodyState, quat_rotate and SHAPE_* come from common.wgsl and the shared
// constants.

// The renderer's constants (208 bytes), written once; `Globals` in src/render/gpu.rs.
struct Globals {
    // world -> clip, reversed depth
    view_proj: mat4x4<f32>,
    // world -> the shadow map's clip space (orthographic along the sun, depth 0..1)
    light_view_proj: mat4x4<f32>,
    // xyz = camera position (m)
    eye: vec4<f32>,
    // xyz = unit vector towards the sun; w = shadow lookups' offset along the normal (m)
    light_dir: vec4<f32>,
    // x = ground height (m), y, z = centre of the drawn square (m), w = its half size (m)
    ground: vec4<f32>,
    // x, y = minor and major grid spacing (m); z, w = where fog starts and is total (m)
    grid: vec4<f32>,
    // rgb = background colour (linear)
    background: vec4<f32>,
}

// One drawn body (32 bytes); `RenderBody` in src/render/gpu.rs. Boxes come
// first, then spheres and capsules (both drawn from the sphere's mesh), then
// hulls by shape (each shape its mesh, in the frame the pose is kept in), so
// each mesh is one instanced draw over a range.
struct RenderBody {
    // box: half extents (m); sphere: the radius in all three; capsule: (radius, half height, radius);
    // hull: 1 in all three (its mesh is in metres)
    half_extents: vec3<f32>,
    // index of the body in the state buffer
    body: u32,
    // linear RGB
    color: vec3<f32>,
    // SHAPE_BOX, SHAPE_SPHERE, SHAPE_CAPSULE or SHAPE_HULL
    shape: u32,
}

// One ball joint (32 bytes); `JointLine` in src/render/gpu.rs. Body -1 is the world.
struct JointLine {
    anchor_a: vec3<f32>,
    body_a: i32,
    anchor_b: vec3<f32>,
    body_b: i32,
}

@group(0) @binding(0) var<uniform> globals: Globals;
@group(0) @binding(1) var<storage, read> states: array<BodyState>;
@group(0) @binding(2) var<storage, read> bodies: array<RenderBody>;
@group(0) @binding(3) var<storage, read> joints: array<JointLine>;
@group(1) @binding(0) var shadow_map: texture_depth_2d;
@group(1) @binding(1) var shadow_sampler: sampler_comparison;

// The share of sunlight reaching a point (0 = shadow), 3x3-filtered; lit outside the map.
fn sunlit(world_pos: vec3<f32>, n: vec3<f32>) -> f32 {
    // move out along the normal by about a texel, so a surface does not shadow itself
    let p = world_pos + n * globals.light_dir.w;
    let c = globals.light_view_proj * vec4<f32>(p, 1.0);
    let uv = vec2<f32>(0.5 + 0.5 * c.x, 0.5 - 0.5 * c.y);
    if any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) || c.z > 1.0 {
        return 1.0;
    }
    // four bilinear comparisons half a texel off centre: a 3x3-texel tent filter
    let h = 0.5 / vec2<f32>(textureDimensions(shadow_map));
    var lit = 0.0;
    lit += textureSampleCompareLevel(shadow_map, shadow_sampler, uv + vec2<f32>(-h.x, -h.y), c.z);
    lit += textureSampleCompareLevel(shadow_map, shadow_sampler, uv + vec2<f32>(h.x, -h.y), c.z);
    lit += textureSampleCompareLevel(shadow_map, shadow_sampler, uv + vec2<f32>(-h.x, h.y), c.z);
    lit += textureSampleCompareLevel(shadow_map, shadow_sampler, uv + vec2<f32>(h.x, h.y), c.z);
    return 0.25 * lit;
}

// Sunlight (with shadows) and a sky/ground ambient on a surface of colour `albedo`.
fn shade(albedo: vec3<f32>, n: vec3<f32>, world_pos: vec3<f32>) -> vec3<f32> {
    let l = globals.light_dir.xyz;
    let diffuse = max(dot(n, l), 0.0) * sunlit(world_pos, n);
    // ambient: bluish sky from above, warm bounce from below
    let ambient = mix(vec3<f32>(0.16, 0.15, 0.14), vec3<f32>(0.30, 0.34, 0.40), 0.5 + 0.5 * n.y);
    let sun = vec3<f32>(1.0, 0.96, 0.90) * 0.85;
    // a faint Blinn-Phong highlight, so curvature shows on spheres
    let v = normalize(globals.eye.xyz - world_pos);
    let h = normalize(l + v);
    let specular = 0.12 * pow(max(dot(n, h), 0.0), 40.0) * select(0.0, 1.0, diffuse > 0.0);
    return albedo * (ambient + sun * diffuse) + vec3<f32>(specular);
}

// Bodies

// A body's point of the unit mesh in world coordinates.
fn body_point(mesh_pos: vec3<f32>, b: RenderBody) -> vec3<f32> {
    let s = states[b.body];
    // the state's quaternion drifts from unit length by rounding only; renormalise anyway
    return s.pos + quat_rotate(normalize(s.rot), mesh_local(mesh_pos, b));
}

// A mesh point in the body's frame: a unit mesh scaled to a box or a sphere
// (a hull's, by 1); a capsule is the sphere's halves moved half its height
// apart along y.
fn mesh_local(mesh_pos: vec3<f32>, b: RenderBody) -> vec3<f32> {
    if b.shape == SHAPE_CAPSULE {
        let r = b.half_extents.x;
        return mesh_pos * r + vec3<f32>(0.0, select(-b.half_extents.y, b.half_extents.y, mesh_pos.y >= 0.0), 0.0);
    }
    return mesh_pos * b.half_extents;
}

// The bodies as the sun sees them: depth only, into the shadow map.
@vertex
fn shadow_vertex(@location(0) mesh_pos: vec3<f32>, @builtin(instance_index) slot: u32) -> @builtin(position) vec4<f32> {
    return globals.light_view_proj * vec4<f32>(body_point(mesh_pos, bodies[slot]), 1.0);
}

struct BodyOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world_pos: vec3<f32>,
    @location(1) world_normal: vec3<f32>,
    // the point in the body's frame (m)
    @location(2) local_pos: vec3<f32>,
    @location(3) @interpolate(flat) half_extents: vec3<f32>,
    @location(4) @interpolate(flat) color: vec3<f32>,
    @location(5) @interpolate(flat) shape: u32,
}

@vertex
fn body_vertex(
    @location(0) mesh_pos: vec3<f32>,
    @location(1) mesh_normal: vec3<f32>,
    @builtin(instance_index) slot: u32,
) -> BodyOut {
    let b = bodies[slot];
    let q = normalize(states[b.body].rot);
    // unit mesh scaled to the body's size, in the body's frame
    let local = mesh_local(mesh_pos, b);
    let world = body_point(mesh_pos, b);
    var out: BodyOut;
    out.clip = globals.view_proj * vec4<f32>(world, 1.0);
    out.world_pos = world;
    // a box's face normals and a sphere's normals survive its (axis-aligned or
    // uniform) scale; a capsule's halves keep theirs, and its sides go between;
    // a hull's faces are unscaled
    out.world_normal = quat_rotate(q, mesh_normal);
    out.local_pos = local;
    out.half_extents = b.half_extents;
    out.color = b.color;
    out.shape = b.shape;
    return out;
}

@fragment
fn body_fragment(in: BodyOut) -> @location(0) vec4<f32> {
    let n = normalize(in.world_normal);
    // box: distance to the nearest edge is the middle one of the distances to the three faces
    let d = max(in.half_extents - abs(in.local_pos), vec3<f32>(0.0));
    let middle = d.x + d.y + d.z - min(d.x, min(d.y, d.z)) - max(d.x, max(d.y, d.z));
    // a darker band about a pixel wide along every edge, so faces read apart (uniform control flow)
    let px = fwidth(middle);
    let edge = 1.0 - smoothstep(0.5 * px, 1.5 * px, middle);
    // sphere or capsule: two tones by octant of the body frame, so a spin shows
    let l = in.local_pos;
    let octant = select(0.0, 1.0, l.x * l.y * l.z < 0.0);
    var albedo = in.color;
    if in.shape == SHAPE_BOX {
        albedo = albedo * (1.0 - 0.5 * edge);
    } else if in.shape != SHAPE_HULL {
        albedo = mix(albedo, vec3<f32>(1.0), 0.5 * octant);
    }
    // a hull keeps its colour: its flat faces already read apart, and turn with it
    return vec4<f32>(shade(albedo, n, in.world_pos), 1.0);
}

// Ground

struct GroundOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world_pos: vec3<f32>,
}

// Two triangles covering the square of half size ground.w around the scene.
@vertex
fn ground_vertex(@builtin(vertex_index) i: u32) -> GroundOut {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(-1.0, 1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(1.0, -1.0),
    );
    let g = globals.ground;
    let c = corners[i] * g.w + g.yz;
    let world = vec3<f32>(c.x, g.x, c.y);
    var out: GroundOut;
    out.clip = globals.view_proj * vec4<f32>(world, 1.0);
    out.world_pos = world;
    return out;
}

// Coverage (0..1) of one-pixel grid lines at integer `coord`, antialiased by the
// screen-space footprint and faded where cells shrink to a few pixels (moiré).
fn grid_lines(coord: vec2<f32>) -> f32 {
    let w = max(fwidth(coord), vec2<f32>(1e-6));
    // distance to the nearest line, in pixels
    let g = abs(fract(coord - 0.5) - 0.5) / w;
    let line = 1.0 - min(min(g.x, g.y), 1.0);
    let fade = 1.0 - smoothstep(0.05, 0.2, max(w.x, w.y));
    return line * fade;
}

@fragment
fn ground_fragment(in: GroundOut) -> @location(0) vec4<f32> {
    let p = in.world_pos.xz;
    let minor = grid_lines(p / globals.grid.x);
    let major = grid_lines(p / globals.grid.y);
    let albedo = vec3<f32>(0.50, 0.50, 0.47) * (1.0 - 0.35 * minor) * (1.0 - 0.5 * major);
    let lit = shade(albedo, vec3<f32>(0.0, 1.0, 0.0), in.world_pos);
    // fog towards the background, so the plane's edge never shows
    let fog = smoothstep(globals.grid.z, globals.grid.w, distance(globals.eye.xyz, in.world_pos));
    return vec4<f32>(mix(lit, globals.background.rgb, fog), 1.0);
}

// Joint lines

struct LineOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec3<f32>,
}

// An anchor in world coordinates: a body's local anchor moved by its pose, or the world's.
fn anchor_world(body: i32, anchor: vec3<f32>) -> vec3<f32> {
    if body < 0 {
        return anchor;
    }
    let s = states[u32(body)];
    return s.pos + quat_rotate(normalize(s.rot), anchor);
}

// The centre a joint's line starts from: the body's, or the anchor for the world.
fn centre_of(body: i32, anchor: vec3<f32>) -> vec3<f32> {
    if body < 0 {
        return anchor;
    }
    return states[u32(body)].pos;
}

// Three segments per joint, two vertices each: centre of A to its anchor, anchor A
// to anchor B (the joint's error, zero when it holds), anchor B to the centre of B.
@vertex
fn joint_vertex(@builtin(vertex_index) v: u32, @builtin(instance_index) j: u32) -> LineOut {
    let jl = joints[j];
    let a = anchor_world(jl.body_a, jl.anchor_a);
    let b = anchor_world(jl.body_b, jl.anchor_b);
    var points = array<vec3<f32>, 6>(centre_of(jl.body_a, a), a, a, b, b, centre_of(jl.body_b, b));
    var out: LineOut;
    out.clip = globals.view_proj * vec4<f32>(points[v], 1.0);
    // the bones pale yellow, the error segment magenta
    out.color = select(vec3<f32>(1.0, 0.9, 0.3), vec3<f32>(0.9, 0.0, 0.9), v / 2u == 1u);
    return out;
}

// Blended at 60% over what is beneath, so a thin body under its line still shows.
@fragment
fn joint_fragment(in: LineOut) -> @location(0) vec4<f32> {
    return vec4<f32>(in.color, 0.6);
}
