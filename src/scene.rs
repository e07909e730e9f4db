// TEMPORARY stub until the real scene module lands (types only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings { pub dt: f32, pub gravity: [f32; 3], pub iterations: u32, pub relaxation: f32, pub linear_damping: f32, pub angular_damping: f32, pub restitution: f32, pub friction: f32, pub substeps: u32 }
impl Default for Settings { fn default() -> Self { Settings { dt: 1.0/60.0, gravity: [0.0,-9.81,0.0], iterations: 8, relaxation: 0.5, linear_damping: 0.0, angular_damping: 0.0, restitution: 0.2, friction: 0.5, substeps: 1 } } }
#[derive(Clone, Debug, PartialEq)] pub struct Ground { pub height: f32 }
#[derive(Clone, Debug, PartialEq)] pub enum Shape { Box { half_extents: [f32; 3] }, Sphere { radius: f32 } }
#[derive(Clone, Debug, PartialEq)] pub struct Body { pub shape: Shape, pub position: [f32; 3], pub orientation: [f32; 4], pub linear_velocity: [f32; 3], pub angular_velocity: [f32; 3], pub mass: f32, pub fixed: bool, pub restitution: Option<f32>, pub friction: Option<f32> }
impl Body {
  pub fn inverse_mass(&self) -> f32 { if self.fixed { 0.0 } else { 1.0 / self.mass } }
  pub fn inverse_inertia(&self) -> [f32; 3] { if self.fixed { return [0.0;3]; } match self.shape { Shape::Box { half_extents: h } => { let m = self.mass; [3.0/(m*(h[1]*h[1]+h[2]*h[2])), 3.0/(m*(h[0]*h[0]+h[2]*h[2])), 3.0/(m*(h[0]*h[0]+h[1]*h[1]))] }, Shape::Sphere { radius } => [2.5/(self.mass*radius*radius); 3] } }
  pub fn bounding_radius(&self) -> f32 { match self.shape { Shape::Box { half_extents: h } => (h[0]*h[0]+h[1]*h[1]+h[2]*h[2]).sqrt(), Shape::Sphere { radius } => radius } }
}
#[derive(Clone, Debug, PartialEq)] pub struct Joint { pub bodies: [i32; 2], pub anchors: [[f32; 3]; 2] }
#[derive(Clone, Debug, PartialEq)] pub struct Camera { pub position: [f32; 3], pub target: [f32; 3], pub fov_y_degrees: f32 }
#[derive(Clone, Debug, PartialEq)] pub struct Scene { pub settings: Settings, pub ground: Option<Ground>, pub bodies: Vec<Body>, pub joints: Vec<Joint>, pub camera: Option<Camera> }
#[derive(Debug, thiserror::Error)] pub enum SceneError { #[error("{0}")] Bad(String) }
impl Scene {
  pub fn from_json_str(_t: &str) -> Result<Scene, SceneError> { Err(SceneError::Bad("stub".into())) }
  pub fn from_path(_p: &std::path::Path) -> Result<Scene, SceneError> { Err(SceneError::Bad("stub".into())) }
  pub fn to_json(&self) -> String { String::new() }
  pub fn validate(&self) -> Result<(), SceneError> { Ok(()) }
}
