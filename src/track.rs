//! Scripted input tracks: user input replayed headless by
//! `verlet run SCENE --input TRACK.json`, or by a program between steps.
//!
//! A track is a JSON object with one list, `events`; each event has a time
//! `t` (s, >= 0) and exactly one action:
//!
//! ```json
//! { "events": [
//!   { "t": 1.0, "impulse": { "body": 7, "impulse": [0, 0, 400], "point": [0.1, 2.0, 0] } },
//!   { "t": 2.0, "explode": { "centre": [0, 1, -1], "strength": 900, "radius": 6, "falloff": 1 } },
//!   { "t": 2.5, "set_pose": { "body": 3, "position": [0, 4, 0], "orientation": [0, 0, 0, 1] } },
//!   { "t": 2.5, "set_velocity": { "body": 3, "linear": [1, 0, 0], "angular": [0, 0, 0] } },
//!   { "t": 3.0, "fixed": { "body": 0, "fixed": true } },
//!   { "t": 3.0, "wind": { "velocity": [8, 0, 0], "duration": 2.0, "gust": 0.3 } }
//! ] }
//! ```
//!
//! - `impulse`: `body`, `impulse` (N s), optional `point` (world
//!   coordinates; absent: the centre of mass), as [`World::apply_impulse`].
//! - `explode`: `centre`, `strength` (N s), `radius` (m), optional `falloff`
//!   (default 1, linear), as [`World::explode`].
//! - `set_pose`: `body`, `position`, `orientation` (`[x, y, z, w]`), as
//!   [`World::set_pose`].
//! - `set_velocity`: `body`, optional `linear` and `angular` (default
//!   zero), as [`World::set_velocity`].
//! - `fixed`: `body`, `fixed` (bool), optional `mass` (kg, for a body made
//!   dynamic), as [`BodyInput::Fixed`].
//! - `wind`: `velocity` (m/s), `duration` (s, > 0), optional `air_density`,
//!   `drag`, `gust`, `gust_period` (defaults of [`Wind`]); it blows before
//!   every step that starts within `[t, t + duration)`, each time for one
//!   step's dt, through [`World::apply_wind`].
//!
//! Events are sorted by time when loaded (stably: events of one time keep
//! their file order). The step that starts at `t_n = n dt` gets the events
//! with `t` in `[t_n, t_n + dt)`; a time less than a thousandth of a step
//! below `t_n` counts as `t_n`, so that 1 s at dt = 1/60 (0.016666668 in
//! f32) is step 60, not step 59.
//!
//! Loading checks what the file alone decides (JSON, unknown or missing
//! fields, non-finite numbers, negative times, times past
//! `limits::MAX_TIME`, values beyond the limits the library's inputs are
//! checked against, sizes); [`Track::check`]
//! checks body indices against a scene's body count. Every error names the
//! field as the scene loader does (`events[2].impulse.body: no body 40 (the
//! scene has 12 bodies)`), with indices as in the file.

use std::path::Path;

use serde::Deserialize;

use crate::json::{path_string, Obj};
use crate::load_error::FileKind;
use crate::scene::{position_problem, speed_problem};
use crate::world::input::{
    air_density_problem, drag_problem, gust_problem, impulse_problem, radius_problem, strength_problem, BodyInput, Point, Wind,
};
use crate::{Error, World};

/// A time less than this many steps below a step's start counts as that
/// step's start.
const STEP_TOLERANCE: f64 = 1e-3;

/// One scripted input.
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// When (s).
    pub t: f64,
    pub action: Action,
}

/// What an [`Event`] does.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    Impulse {
        body: usize,
        impulse: [f32; 3],
        point: Option<[f32; 3]>,
    },
    Explode {
        centre: [f32; 3],
        strength: f32,
        radius: f32,
        falloff: f32,
    },
    SetPose {
        body: usize,
        position: [f32; 3],
        orientation: [f32; 4],
    },
    SetVelocity {
        body: usize,
        linear: [f32; 3],
        angular: [f32; 3],
    },
    Fixed {
        body: usize,
        fixed: bool,
        mass: Option<f32>,
    },
    /// `wind` blows before every step starting within `[t, t + duration)`.
    Wind {
        wind: Wind,
        duration: f32,
    },
}

impl Action {
    /// The JSON key of this action.
    pub fn name(&self) -> &'static str {
        match self {
            Action::Impulse { .. } => "impulse",
            Action::Explode { .. } => "explode",
            Action::SetPose { .. } => "set_pose",
            Action::SetVelocity { .. } => "set_velocity",
            Action::Fixed { .. } => "fixed",
            Action::Wind { .. } => "wind",
        }
    }

    fn body(&self) -> Option<usize> {
        match *self {
            Action::Impulse { body, .. }
            | Action::SetPose { body, .. }
            | Action::SetVelocity { body, .. }
            | Action::Fixed { body, .. } => Some(body),
            Action::Explode { .. } | Action::Wind { .. } => None,
        }
    }

    fn body_input(&self) -> Option<BodyInput> {
        Some(match *self {
            Action::Impulse { body, impulse, point } => {
                BodyInput::Impulse { body, impulse, point: point.map_or(Point::Centre, Point::World) }
            }
            Action::SetPose { body, position, orientation } => BodyInput::Pose { body, position, orientation },
            Action::SetVelocity { body, linear, angular } => BodyInput::Velocity { body, linear, angular },
            Action::Fixed { body, fixed, mass } => BodyInput::Fixed { body, fixed, mass },
            Action::Explode { .. } | Action::Wind { .. } => return None,
        })
    }
}

/// The first key of a scene's top level (`bodies`, `settings`, ...) that
/// `text` has, if it is a JSON object without `events`: a scene given as a
/// track. Asked only of text that failed to load as a track.
fn scene_key(text: &str) -> Option<String> {
    let top: serde_json::Map<String, serde_json::Value> = serde_json::from_str(text).ok()?;
    if top.contains_key("events") {
        return None;
    }
    ["bodies", "settings", "ground", "joints", "camera"].iter().find(|k| top.contains_key(**k)).map(|k| k.to_string())
}

/// A list of events sorted by time; see the module documentation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Track {
    events: Vec<Event>,
    /// Each event's index in the file (or the list given to [`Track::new`]).
    origin: Vec<usize>,
}

/// Why a track could not be loaded: the error type it shares with scenes
/// (`crate::load_error`).
pub type TrackError = crate::load_error::LoadError;

impl Track {
    /// A track of these events (in any order; sorted stably by time here),
    /// each checked as a loaded one is (`events[k]...` names the k-th).
    pub fn new(events: Vec<Event>) -> Result<Track, TrackError> {
        for (k, e) in events.iter().enumerate() {
            validate_event(e, &format!("events[{k}]"))?;
        }
        let mut pairs: Vec<(usize, Event)> = events.into_iter().enumerate().collect();
        pairs.sort_by(|a, b| a.1.t.total_cmp(&b.1.t)); // stable
        let (origin, events) = pairs.into_iter().unzip();
        Ok(Track { events, origin })
    }

    /// Parses and checks a track from JSON text (body indices are checked
    /// against a scene by [`Track::check`]).
    pub fn from_json_str(text: &str) -> Result<Track, TrackError> {
        TrackError::check_text(FileKind::Track, text)?;
        let mut deserializer = serde_json::Deserializer::from_str(text);
        let Obj(raw): Obj<RawTrack> =
            serde_path_to_error::deserialize(&mut deserializer).map_err(|error| match scene_key(text) {
                Some(key) => TrackError::SceneGiven(key),
                None => json_error(path_string(error.path()), error.into_inner()),
            })?;
        deserializer.end().map_err(|error| json_error(None, error))?;
        let raw_events = raw.events.ok_or_else(|| TrackError::invalid("events", "is required but missing"))?;
        let mut events = Vec::with_capacity(raw_events.len());
        for (k, Obj(e)) in raw_events.into_iter().enumerate() {
            events.push(e.into_event(&format!("events[{k}]"))?);
        }
        Track::new(events)
    }

    /// Reads and checks a track file.
    pub fn from_path(path: &Path) -> Result<Track, TrackError> {
        Track::from_json_str(&TrackError::read(FileKind::Track, path)?)
    }

    /// Refuses an event naming a body a scene of `body_count` bodies lacks.
    pub fn check(&self, body_count: usize) -> Result<(), TrackError> {
        // report the first bad event in file order
        let mut bad: Option<(usize, &Event)> = None;
        for (e, &k) in self.events.iter().zip(&self.origin) {
            if e.action.body().is_some_and(|b| b >= body_count) && bad.is_none_or(|(j, _)| k < j) {
                bad = Some((k, e));
            }
        }
        match bad {
            None => Ok(()),
            Some((k, e)) => Err(TrackError::invalid(
                format!("events[{k}].{}.body", e.action.name()),
                format!("no body {} (the scene has {body_count} bodies)", e.action.body().unwrap_or(0)),
            )),
        }
    }

    /// Refuses a `fixed` event's mass that the body's shape makes unusable
    /// (an inverse mass or inertia f32 cannot hold), naming the event, as the
    /// scene's own masses are refused; [`Track::check`] first.
    pub fn check_masses(&self, scene: &crate::Scene) -> Result<(), TrackError> {
        for (e, &k) in self.events.iter().zip(&self.origin) {
            if let Action::Fixed { body, mass: Some(m), .. } = e.action {
                if let Some(why) = scene.bodies.get(body).and_then(|b| crate::scene::mass_problem(&b.shape, m)) {
                    return Err(TrackError::invalid(format!("events[{k}].fixed.mass"), why));
                }
            }
        }
        Ok(())
    }

    /// The events, sorted by time.
    pub fn events(&self) -> &[Event] {
        &self.events
    }

    pub fn is_empty(&self) -> bool {
        self.events.is_empty()
    }

    /// The step (0-based) before which an event at time `t` is applied,
    /// for steps of `dt`.
    pub fn step_of(t: f64, dt: f32) -> u64 {
        (t / dt as f64 + STEP_TOLERANCE).floor().max(0.0) as u64
    }

    /// Steps `[first, end)` that the event acts before.
    fn steps(e: &Event, dt: f32) -> (u64, u64) {
        let first = Track::step_of(e.t, dt);
        match &e.action {
            Action::Wind { duration, .. } => (first, Track::step_of(e.t + *duration as f64, dt).max(first.saturating_add(1))),
            _ => (first, first.saturating_add(1)),
        }
    }

    /// The events (their indices in the file, and their actions' names)
    /// that act before any step of `steps`, for steps of `dt`: what to name
    /// when a body is found absurd there.
    pub fn acting_before(&self, steps: std::ops::RangeInclusive<u64>, dt: f32) -> Vec<(usize, &'static str)> {
        let mut acting: Vec<(usize, &'static str)> = self
            .events
            .iter()
            .zip(&self.origin)
            .filter(|(e, _)| {
                let (first, end) = Track::steps(e, dt);
                first <= *steps.end() && end > *steps.start()
            })
            .map(|(e, &k)| (k, e.action.name()))
            .collect();
        acting.sort();
        acting
    }

    /// The first step at or after `step` before which this track does
    /// anything, for steps of `dt`.
    pub fn next_input_step(&self, step: u64, dt: f32) -> Option<u64> {
        let mut next: Option<u64> = None;
        for e in &self.events {
            let (first, end) = Track::steps(e, dt);
            if end > step {
                let at = first.max(step);
                next = Some(next.map_or(at, |n| n.min(at)));
            }
            if first >= step {
                break; // sorted: later events start later still
            }
        }
        next
    }

    /// Applies what is due before the world's next step (step n, starting at
    /// n dt): the events with `t` in `[n dt, (n + 1) dt)` in order, then
    /// every wind still blowing. Returns how many events acted. Nothing is
    /// applied if a due event names a body the world lacks.
    pub fn apply(&self, world: &mut World) -> Result<usize, Error> {
        let step = world.step_count();
        let dt = world.settings().dt;
        let bodies = world.body_count();
        let mut due: Vec<(usize, &Event)> = Vec::new();
        let mut winds: Vec<&Wind> = Vec::new();
        for (e, &k) in self.events.iter().zip(&self.origin) {
            let (first, end) = Track::steps(e, dt);
            if first > step {
                break;
            }
            if step >= end {
                continue;
            }
            if let Action::Wind { wind, .. } = &e.action {
                winds.push(wind);
            } else {
                if let Some(b) = e.action.body().filter(|&b| b >= bodies) {
                    return Err(Error::Input(format!(
                        "events[{k}].{}.body: no body {b} (the world has {bodies} bodies)",
                        e.action.name()
                    )));
                }
                due.push((k, e));
            }
        }
        // Runs of body inputs go as one batch, and runs of explosions as
        // another, each keeping its place; the winds go together last.
        let mut batch: Vec<BodyInput> = Vec::new();
        let mut blasts: Vec<([f32; 3], f32, f32, f32)> = Vec::new();
        for (_, e) in &due {
            match e.action.body_input() {
                Some(input) => {
                    if !blasts.is_empty() {
                        world.explode_all(&std::mem::take(&mut blasts))?;
                    }
                    batch.push(input);
                }
                None => {
                    if !batch.is_empty() {
                        world.apply_inputs(&std::mem::take(&mut batch))?;
                    }
                    if let Action::Explode { centre, strength, radius, falloff } = e.action {
                        blasts.push((centre, strength, radius, falloff));
                    }
                }
            }
        }
        if !batch.is_empty() {
            world.apply_inputs(&batch)?;
        }
        if !blasts.is_empty() {
            world.explode_all(&blasts)?;
        }
        if !winds.is_empty() {
            let blowing: Vec<(Wind, f32)> = winds.iter().map(|&&w| (w, dt)).collect();
            world.apply_winds(&blowing)?;
        }
        Ok(due.len() + winds.len())
    }

    /// The track as JSON text that [`Track::from_json_str`] reads back.
    pub fn to_json(&self) -> String {
        let events: Vec<serde_json::Value> = self
            .events
            .iter()
            .map(|e| {
                let body = match &e.action {
                    Action::Impulse { body, impulse, point } => {
                        let mut v = serde_json::json!({ "body": body, "impulse": impulse });
                        if let Some(p) = point {
                            v["point"] = serde_json::json!(p);
                        }
                        v
                    }
                    Action::Explode { centre, strength, radius, falloff } => serde_json::json!({
                        "centre": centre, "strength": strength, "radius": radius, "falloff": falloff
                    }),
                    Action::SetPose { body, position, orientation } => serde_json::json!({
                        "body": body, "position": position, "orientation": orientation
                    }),
                    Action::SetVelocity { body, linear, angular } => serde_json::json!({
                        "body": body, "linear": linear, "angular": angular
                    }),
                    Action::Fixed { body, fixed, mass } => {
                        let mut v = serde_json::json!({ "body": body, "fixed": fixed });
                        if let Some(m) = mass {
                            v["mass"] = serde_json::json!(m);
                        }
                        v
                    }
                    Action::Wind { wind, duration } => serde_json::json!({
                        "velocity": wind.velocity, "duration": duration, "air_density": wind.air_density,
                        "drag": wind.drag, "gust": wind.gust, "gust_period": wind.gust_period
                    }),
                };
                let mut event = serde_json::json!({ "t": e.t });
                event[e.action.name()] = body;
                event
            })
            .collect();
        serde_json::to_string_pretty(&serde_json::json!({ "events": events })).expect("plain JSON values always serialise")
    }
}

// ---------------------------------------------------------------------------
// Checks
// ---------------------------------------------------------------------------

fn validate_event(e: &Event, path: &str) -> Result<(), TrackError> {
    use crate::limits::MAX_TIME;
    if !(e.t.is_finite() && e.t >= 0.0) {
        return Err(TrackError::invalid(format!("{path}.t"), format!("must be a finite time >= 0 s, got {}", e.t)));
    }
    if e.t > MAX_TIME {
        return Err(TrackError::invalid(
            format!("{path}.t"),
            format!("is {:e} s, past {MAX_TIME:e} s, the latest time a world reaches", e.t),
        ));
    }
    let at = |field: &str| format!("{path}.{}.{field}", e.action.name());
    match &e.action {
        Action::Impulse { impulse, point, .. } => {
            finite(impulse, &at("impulse"))?;
            sane(impulse_problem(*impulse), &at("impulse"))?;
            if let Some(p) = point {
                finite(p, &at("point"))?;
                sane(position_problem(*p), &at("point"))?;
            }
        }
        Action::Explode { centre, strength, radius, falloff } => {
            finite(centre, &at("centre"))?;
            sane(position_problem(*centre), &at("centre"))?;
            finite(&[*strength], &at("strength"))?;
            sane(strength_problem(*strength), &at("strength"))?;
            at_least(*radius, &at("radius"), 0.0, false)?;
            sane(radius_problem(*radius), &at("radius"))?;
            at_least(*falloff, &at("falloff"), 0.0, true)?;
        }
        Action::SetPose { position, orientation, .. } => {
            finite(position, &at("position"))?;
            sane(position_problem(*position), &at("position"))?;
            finite(orientation, &at("orientation"))?;
            let norm = orientation.iter().map(|&v| (v as f64) * (v as f64)).sum::<f64>().sqrt();
            if norm < 1e-6 {
                return Err(TrackError::invalid(at("orientation"), "must be a non-zero quaternion [x, y, z, w]"));
            }
        }
        Action::SetVelocity { linear, angular, .. } => {
            finite(linear, &at("linear"))?;
            sane(speed_problem(*linear), &at("linear"))?;
            finite(angular, &at("angular"))?;
            // the turn per substep is checked when applied, against the world's dt
            if let Some(why) = crate::scene::spin_problem(*angular, 0.0) {
                return Err(TrackError::invalid(at("angular"), why));
            }
        }
        Action::Fixed { mass, .. } => {
            if let Some(m) = mass {
                at_least(*m, &at("mass"), 0.0, false)?;
            }
        }
        Action::Wind { wind, duration } => {
            finite(&wind.velocity, &at("velocity"))?;
            // the drag pulls a body toward the wind's velocity
            sane(speed_problem(wind.velocity), &at("velocity"))?;
            at_least(wind.air_density, &at("air_density"), 0.0, true)?;
            at_least(wind.drag, &at("drag"), 0.0, true)?;
            at_least(wind.gust, &at("gust"), 0.0, true)?;
            sane(gust_problem(wind.velocity, wind.gust), &at("gust"))?;
            sane(air_density_problem(wind.air_density), &at("air_density"))?;
            sane(drag_problem(wind.drag), &at("drag"))?;
            at_least(wind.gust_period, &at("gust_period"), 0.0, false)?;
            at_least(*duration, &at("duration"), 0.0, false)?;
            if *duration as f64 > MAX_TIME {
                return Err(TrackError::invalid(at("duration"), format!("is {duration:e} s, past {MAX_TIME:e} s")));
            }
        }
    }
    Ok(())
}

/// Refuses what `problem` found wrong (scene::position_problem, ...).
fn sane(problem: Option<String>, path: &str) -> Result<(), TrackError> {
    problem.map_or(Ok(()), |why| Err(TrackError::invalid(path, why)))
}

fn finite(values: &[f32], path: &str) -> Result<(), TrackError> {
    for (k, v) in values.iter().enumerate() {
        if !v.is_finite() {
            let at = if values.len() > 1 { format!("{path}[{k}]") } else { path.to_string() };
            return Err(TrackError::invalid(at, format!("must be a finite number, got {v}")));
        }
    }
    Ok(())
}

/// `v` finite and > `low` (or >= with `or_equal`).
fn at_least(v: f32, path: &str, low: f32, or_equal: bool) -> Result<(), TrackError> {
    finite(&[v], path)?;
    if v > low || (or_equal && v == low) {
        Ok(())
    } else {
        let op = if or_equal { ">=" } else { ">" };
        Err(TrackError::invalid(path, format!("must be {op} {low}, got {v}")))
    }
}

// ---------------------------------------------------------------------------
// The file's raw form (as in scene/load.rs: every field optional so that a missing
// one is named, lists as Vec so that a wrong length is named)
// ---------------------------------------------------------------------------

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTrack {
    events: Option<Vec<Obj<RawEvent>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEvent {
    t: Option<f64>,
    impulse: Option<Obj<RawImpulse>>,
    explode: Option<Obj<RawExplode>>,
    set_pose: Option<Obj<RawPose>>,
    set_velocity: Option<Obj<RawVelocity>>,
    fixed: Option<Obj<RawFixed>>,
    wind: Option<Obj<RawWind>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawImpulse {
    body: Option<u64>,
    impulse: Option<Vec<f32>>,
    point: Option<Vec<f32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawExplode {
    centre: Option<Vec<f32>>,
    strength: Option<f32>,
    radius: Option<f32>,
    falloff: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPose {
    body: Option<u64>,
    position: Option<Vec<f32>>,
    orientation: Option<Vec<f32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawVelocity {
    body: Option<u64>,
    linear: Option<Vec<f32>>,
    angular: Option<Vec<f32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFixed {
    body: Option<u64>,
    fixed: Option<bool>,
    mass: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWind {
    velocity: Option<Vec<f32>>,
    duration: Option<f32>,
    air_density: Option<f32>,
    drag: Option<f32>,
    gust: Option<f32>,
    gust_period: Option<f32>,
}

fn required<T>(v: Option<T>, path: &str) -> Result<T, TrackError> {
    v.ok_or_else(|| TrackError::invalid(path, "is required but missing"))
}

fn exact<const N: usize>(values: Vec<f32>, path: &str) -> Result<[f32; N], TrackError> {
    let len = values.len();
    values.try_into().map_err(|_| TrackError::invalid(path, format!("must have exactly {N} elements, got {len}")))
}

fn body_index(v: Option<u64>, path: &str) -> Result<usize, TrackError> {
    let b = required(v, path)?;
    usize::try_from(b).map_err(|_| TrackError::invalid(path, format!("no body {b}")))
}

impl RawEvent {
    fn into_event(self, path: &str) -> Result<Event, TrackError> {
        let t = required(self.t, &format!("{path}.t"))?;
        let given = [
            self.impulse.is_some(),
            self.explode.is_some(),
            self.set_pose.is_some(),
            self.set_velocity.is_some(),
            self.fixed.is_some(),
            self.wind.is_some(),
        ];
        if given.iter().filter(|&&g| g).count() != 1 {
            return Err(TrackError::invalid(
                path,
                "must have exactly one of impulse, explode, set_pose, set_velocity, fixed, wind",
            ));
        }
        let at = |name: &str, field: &str| format!("{path}.{name}.{field}");
        let action = if let Some(Obj(r)) = self.impulse {
            let f = |field| at("impulse", field);
            Action::Impulse {
                body: body_index(r.body, &f("body"))?,
                impulse: exact(required(r.impulse, &f("impulse"))?, &f("impulse"))?,
                point: r.point.map(|p| exact(p, &f("point"))).transpose()?,
            }
        } else if let Some(Obj(r)) = self.explode {
            let f = |field| at("explode", field);
            Action::Explode {
                centre: exact(required(r.centre, &f("centre"))?, &f("centre"))?,
                strength: required(r.strength, &f("strength"))?,
                radius: required(r.radius, &f("radius"))?,
                falloff: r.falloff.unwrap_or(1.0),
            }
        } else if let Some(Obj(r)) = self.set_pose {
            let f = |field| at("set_pose", field);
            Action::SetPose {
                body: body_index(r.body, &f("body"))?,
                position: exact(required(r.position, &f("position"))?, &f("position"))?,
                orientation: exact(required(r.orientation, &f("orientation"))?, &f("orientation"))?,
            }
        } else if let Some(Obj(r)) = self.set_velocity {
            let f = |field| at("set_velocity", field);
            Action::SetVelocity {
                body: body_index(r.body, &f("body"))?,
                linear: r.linear.map(|v| exact(v, &f("linear"))).transpose()?.unwrap_or([0.0; 3]),
                angular: r.angular.map(|v| exact(v, &f("angular"))).transpose()?.unwrap_or([0.0; 3]),
            }
        } else if let Some(Obj(r)) = self.fixed {
            let f = |field| at("fixed", field);
            Action::Fixed { body: body_index(r.body, &f("body"))?, fixed: required(r.fixed, &f("fixed"))?, mass: r.mass }
        } else if let Some(Obj(r)) = self.wind {
            let f = |field| at("wind", field);
            let d = Wind::default();
            Action::Wind {
                wind: Wind {
                    velocity: exact(required(r.velocity, &f("velocity"))?, &f("velocity"))?,
                    air_density: r.air_density.unwrap_or(d.air_density),
                    drag: r.drag.unwrap_or(d.drag),
                    gust: r.gust.unwrap_or(d.gust),
                    gust_period: r.gust_period.unwrap_or(d.gust_period),
                },
                duration: required(r.duration, &f("duration"))?,
            }
        } else {
            unreachable!("exactly one action was checked above")
        };
        Ok(Event { t, action })
    }
}

// ---------------------------------------------------------------------------
// JSON errors, as scene/load.rs reports them
// ---------------------------------------------------------------------------

fn json_error(field: Option<String>, inner: serde_json::Error) -> TrackError {
    TrackError::from_json(FileKind::Track, field, inner)
}
