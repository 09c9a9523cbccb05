//! The quadruped of SPEC §7: body a × b, hips at the corners, each foot in an annular-sector
//! workspace around its hip, feet fixed in the world while planted; static stability and the
//! workspace checks of body moves along the whole motion (analytically, see [`max_rotation`] and
//! [`max_translation`]).

use crate::error::GaitError;
use nalgebra::{Point2, Vector2};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_4, PI};

/// Slack of every workspace and stability test (\[j\] or rad): rounding in the rules' arithmetic
/// (a foot placed on L = 2 exactly lands within 1e-15 of it) must not make a boundary state
/// invalid. 1e-9 is a millionth of the key quantum's default, so it never merges two states.
pub const TOLERANCE: f64 = 1e-9;

/// Which extreme of each sector Tab. 1's "max angle" names (SPEC §7, revised Decision).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LegAngleReading {
    /// "max angle" is the forward extreme (toward +y_r, the direction of motion): 3π/4 for legs
    /// 0, 1 and π/4 for legs 2, 3. The SPEC's Decision, the one that reproduces the paper.
    #[default]
    Forward,
    /// "max angle" is the rearward extreme (5π/4 for legs 0, 1, 7π/4 ≡ −π/4 for legs 2, 3), the
    /// literal reading of Tab. 1 with counter-clockwise angles.
    Rearward,
}

impl std::str::FromStr for LegAngleReading {
    type Err = GaitError;
    fn from_str(s: &str) -> Result<Self, GaitError> {
        match s {
            "forward" => Ok(LegAngleReading::Forward),
            "rearward" => Ok(LegAngleReading::Rearward),
            other => Err(GaitError::UnknownReading(other.to_string())),
        }
    }
}

/// One leg's workspace: an annular sector around its hip, in the body frame (Tab. 1). Built by
/// [`Workspace::new`], which also keeps the sector edges' unit vectors for the motion checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Workspace {
    l_min: f64,
    l_max: f64,
    forward_angle: f64,
    rearward_angle: f64,
    nominal_angle: f64,
    nominal_length: f64,
    /// Unit vectors of the clockwise and counter-clockwise edges.
    edges: [Vector2<f64>; 2],
}

impl Workspace {
    /// The sector L ∈ [l_min, l_max], β between `rearward_angle` and `forward_angle` through
    /// `nominal_angle`, with the nominal ("middle") length `nominal_length`.
    pub fn new(
        l_min: f64,
        l_max: f64,
        forward_angle: f64,
        rearward_angle: f64,
        nominal_angle: f64,
        nominal_length: f64,
    ) -> Self {
        let (lo, hi) = if wrap(forward_angle - nominal_angle) > 0.0 {
            (rearward_angle, forward_angle)
        } else {
            (forward_angle, rearward_angle)
        };
        Workspace {
            l_min,
            l_max,
            forward_angle,
            rearward_angle,
            nominal_angle,
            nominal_length,
            edges: [unit(lo), unit(hi)],
        }
    }

    /// Shortest leg L_min \[j\].
    pub fn l_min(&self) -> f64 {
        self.l_min
    }

    /// Longest leg L_max \[j\].
    pub fn l_max(&self) -> f64 {
        self.l_max
    }

    /// The sector's forward extreme β (toward +y_r) \[rad\].
    pub fn forward_angle(&self) -> f64 {
        self.forward_angle
    }

    /// The sector's rearward extreme β \[rad\].
    pub fn rearward_angle(&self) -> f64 {
        self.rearward_angle
    }

    /// The nominal angle β, inside the sector \[rad\].
    pub fn nominal_angle(&self) -> f64 {
        self.nominal_angle
    }

    /// The nominal ("middle") length \[j\].
    pub fn nominal_length(&self) -> f64 {
        self.nominal_length
    }

    /// The sector's clockwise and counter-clockwise extremes (lo, hi), hi − lo ∈ (0, π).
    pub fn sector(&self) -> (f64, f64) {
        if wrap(self.forward_angle - self.nominal_angle) > 0.0 {
            (self.rearward_angle, self.forward_angle)
        } else {
            (self.forward_angle, self.rearward_angle)
        }
    }

    /// Whether a foot at `p` from the hip (body frame) lies in the sector, within [`TOLERANCE`].
    pub fn contains(&self, p: Vector2<f64>) -> bool {
        let r2 = p.norm_squared();
        let [elo, ehi] = self.edges;
        r2 >= self.l_min * self.l_min - TOLERANCE
            && r2 <= self.l_max * self.l_max + TOLERANCE
            && cross(elo, p) >= -TOLERANCE
            && cross(p, ehi) >= -TOLERANCE
    }
}

/// The robot: body, hips, workspaces, and which extreme "max angle" means.
///
/// Legs (SPEC §7 Decision): 0 front left, 1 rear left (−x_r side), 2 front right, 3 rear right
/// (+x_r side); front is +y_r, the direction of motion. The centre of gravity is the body centre.
#[derive(Debug, Clone, PartialEq)]
pub struct QuadrupedModel {
    /// Body width a along x_r \[j\].
    pub a: f64,
    /// Body length b along y_r \[j\].
    pub b: f64,
    /// Hip of each leg in the body frame \[j\].
    pub hips: [Vector2<f64>; 4],
    /// Workspace of each leg.
    pub workspaces: [Workspace; 4],
    /// Which extreme the rules' "max angle" is.
    pub reading: LegAngleReading,
}

impl Default for QuadrupedModel {
    /// The paper's robot (Tab. 1): a = 2, b = 3, L ∈ [1, 2], sectors ±π/4 around π (legs 0, 1)
    /// and 0 (legs 2, 3), nominal length 1.5, forward reading.
    fn default() -> Self {
        QuadrupedModel::paper(LegAngleReading::Forward)
    }
}

impl QuadrupedModel {
    /// The paper's robot (Tab. 1) under the given reading.
    pub fn paper(reading: LegAngleReading) -> Self {
        let (a, b) = (2.0, 3.0);
        let left = Workspace::new(1.0, 2.0, 3.0 * FRAC_PI_4, 5.0 * FRAC_PI_4, PI, 1.5);
        let right = Workspace::new(1.0, 2.0, FRAC_PI_4, -FRAC_PI_4, 0.0, 1.5);
        QuadrupedModel {
            a,
            b,
            hips: [
                Vector2::new(-a / 2.0, b / 2.0),
                Vector2::new(-a / 2.0, -b / 2.0),
                Vector2::new(a / 2.0, b / 2.0),
                Vector2::new(a / 2.0, -b / 2.0),
            ],
            workspaces: [left, left, right, right],
            reading,
        }
    }

    /// The same robot under another reading.
    pub fn with_reading(&self, reading: LegAngleReading) -> Self {
        QuadrupedModel {
            reading,
            ..self.clone()
        }
    }

    /// The rules' "max angle" of leg `leg` under the model's reading.
    pub fn max_angle(&self, leg: usize) -> f64 {
        let w = &self.workspaces[leg];
        match self.reading {
            LegAngleReading::Forward => w.forward_angle,
            LegAngleReading::Rearward => w.rearward_angle,
        }
    }

    /// The rules' "min angle" of leg `leg` (the other extreme).
    pub fn min_angle(&self, leg: usize) -> f64 {
        let w = &self.workspaces[leg];
        match self.reading {
            LegAngleReading::Forward => w.rearward_angle,
            LegAngleReading::Rearward => w.forward_angle,
        }
    }

    /// Leg `leg`'s foot at polar (L, β) from its hip, in the body frame.
    pub fn foot_in_body(&self, leg: usize, length: f64, angle: f64) -> Vector2<f64> {
        self.hips[leg] + length * unit(angle)
    }

    /// Checks the model: positive sizes, sectors narrower than π, the nominal foot inside.
    pub fn validate(&self) -> Result<(), GaitError> {
        let finite_pos = |name, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(GaitError::InvalidParameter {
                    name,
                    value: v,
                    reason: "must be finite and > 0",
                })
            }
        };
        finite_pos("a", self.a)?;
        finite_pos("b", self.b)?;
        for (leg, w) in self.workspaces.iter().enumerate() {
            finite_pos("l_min", w.l_min)?;
            if !(w.l_max > w.l_min && w.l_max.is_finite()) {
                return Err(GaitError::InvalidParameter {
                    name: "l_max",
                    value: w.l_max,
                    reason: "must be finite and > l_min",
                });
            }
            let (lo, hi) = w.sector();
            let width = wrap(hi - lo);
            if !(width > 0.0 && width < PI) {
                return Err(GaitError::InvalidParameter {
                    name: "sector",
                    value: width,
                    reason: "each sector must be narrower than π",
                });
            }
            let nominal = w.nominal_length * unit(w.nominal_angle);
            if !w.contains(nominal) {
                return Err(GaitError::InvalidState(format!(
                    "leg {leg}'s nominal foot is outside its workspace"
                )));
            }
        }
        Ok(())
    }
}

/// The body's pose in the world: centre (x, y) and φ, the angle of x_r to x \[rad\].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BodyPose {
    /// Centre x \[j\].
    pub x: f64,
    /// Centre y \[j\].
    pub y: f64,
    /// Angle of x_r to the world's x \[rad\].
    pub phi: f64,
}

impl BodyPose {
    /// The body centre (and centre of gravity) in the world.
    pub fn centre(&self) -> Point2<f64> {
        Point2::new(self.x, self.y)
    }

    /// A body-frame vector in world axes.
    pub fn to_world(&self, v: Vector2<f64>) -> Vector2<f64> {
        rotate(v, self.phi)
    }

    /// A world point in the body frame.
    pub fn point_in_body(&self, p: Point2<f64>) -> Vector2<f64> {
        rotate(p - self.centre(), -self.phi)
    }

    /// The unit vector of y_r (the direction of motion) in the world.
    pub fn forward(&self) -> Vector2<f64> {
        unit(self.phi + PI / 2.0)
    }
}

/// A state of the search: the body pose and the world positions of the four feet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaitState {
    /// The body's pose.
    pub body: BodyPose,
    /// World position of the foot of legs 0..3.
    pub feet: [Point2<f64>; 4],
}

impl GaitState {
    /// The body at `body` with every leg nominal (middle length, nominal angle).
    pub fn nominal(model: &QuadrupedModel, body: BodyPose) -> Self {
        let feet = std::array::from_fn(|leg| {
            let w = &model.workspaces[leg];
            let p = model.foot_in_body(leg, w.nominal_length, w.nominal_angle);
            body.centre() + body.to_world(p)
        });
        GaitState { body, feet }
    }

    /// Leg `leg`'s foot relative to its hip, in the body frame.
    pub fn foot_from_hip(&self, model: &QuadrupedModel, leg: usize) -> Vector2<f64> {
        self.body.point_in_body(self.feet[leg]) - model.hips[leg]
    }

    /// Leg `leg`'s polar coordinates (L, β) from its hip.
    pub fn polar(&self, model: &QuadrupedModel, leg: usize) -> (f64, f64) {
        let p = self.foot_from_hip(model, leg);
        (p.norm(), p.y.atan2(p.x))
    }

    /// Whether every foot lies in its workspace (within [`TOLERANCE`]).
    pub fn in_workspaces(&self, model: &QuadrupedModel) -> bool {
        (0..4).all(|leg| model.workspaces[leg].contains(self.foot_from_hip(model, leg)))
    }

    /// Whether every coordinate is finite.
    pub fn is_finite(&self) -> bool {
        let b = &self.body;
        b.x.is_finite()
            && b.y.is_finite()
            && b.phi.is_finite()
            && self.feet.iter().all(|f| f.x.is_finite() && f.y.is_finite())
    }
}

/// Signed distance of `c` inside the triangle (p, q, r): the least distance to its edges,
/// negative outside; −∞ for a degenerate (collinear) triangle.
pub fn triangle_margin(p: Point2<f64>, q: Point2<f64>, r: Point2<f64>, c: Point2<f64>) -> f64 {
    let area2 = cross(q - p, r - p);
    if area2.abs() < 1e-12 {
        return f64::NEG_INFINITY;
    }
    let s = area2.signum();
    [(p, q), (q, r), (r, p)]
        .iter()
        .map(|&(u, v)| s * cross(v - u, c - u) / (v - u).norm())
        .fold(f64::INFINITY, f64::min)
}

/// Signed distance of `c` inside the convex hull of four points (negative outside).
pub fn hull_margin(pts: &[Point2<f64>; 4], c: Point2<f64>) -> f64 {
    // The margin of a convex polygon is the least distance to its edges; an edge of the hull of
    // four points is a pair with the other two on one side (collinear counts as either side).
    let mut best = f64::INFINITY;
    let mut any = false;
    for i in 0..4 {
        for j in (i + 1)..4 {
            let (u, v) = (pts[i], pts[j]);
            let d = v - u;
            let len = d.norm();
            if len < 1e-12 {
                continue;
            }
            let (mut pos, mut neg) = (true, true);
            for (k, p) in pts.iter().enumerate() {
                if k != i && k != j {
                    let s = cross(d, p - u);
                    pos &= s >= -1e-12;
                    neg &= s <= 1e-12;
                }
            }
            let sign = if pos {
                1.0
            } else if neg {
                -1.0
            } else {
                continue;
            };
            any = true;
            best = best.min(sign * cross(d, c - u) / len);
        }
    }
    if any {
        best
    } else {
        f64::NEG_INFINITY
    }
}

/// Whether the state stands with leg `lifted_leg` in the air: the centre of gravity lies inside
/// the triangle of the other three feet by at least `margin` (SPEC §7 Decision).
pub fn is_stable(model: &QuadrupedModel, margin: f64, state: &GaitState, lifted_leg: usize) -> bool {
    let _ = model;
    let f = &state.feet;
    let [p, q, r] = match lifted_leg {
        0 => [f[1], f[2], f[3]],
        1 => [f[0], f[2], f[3]],
        2 => [f[0], f[1], f[3]],
        _ => [f[0], f[1], f[2]],
    };
    triangle_margin(p, q, r, state.body.centre()) >= margin - TOLERANCE
}

/// Whether the state stands on all four feet: the centre inside their convex hull by `margin`.
pub fn is_supported(margin: f64, state: &GaitState) -> bool {
    hull_margin(&state.feet, state.body.centre()) >= margin - TOLERANCE
}

/// The largest rotation of the body about its centre in the direction `sign` (+1
/// counter-clockwise, −1 clockwise), at most `limit` \[rad\] (≤ π), that keeps every foot in its
/// workspace along the whole motion. Exact: each boundary (|p|² = L², the two sector edges) is
/// a sinusoid A cos t + B sin t + C of the rotation angle t, solved in closed form. A constraint
/// the start state meets only within [`TOLERANCE`] may not get worse.
pub fn max_rotation(model: &QuadrupedModel, state: &GaitState, sign: f64, limit: f64) -> f64 {
    let mut t_max = limit.clamp(0.0, PI);
    for leg in 0..4 {
        // Foot from the body centre, body frame: q. Rotating the body by σt turns q by −σt:
        // R(−σt) q = (qx cos t + σ qy sin t, −σ qx sin t + qy cos t).
        let q = state.body.point_in_body(state.feet[leg]);
        let h = model.hips[leg];
        let w = &model.workspaces[leg];
        // p(t) = R(−σt) q − h; u·p = cos t (u·q) + σ sin t (ux qy − uy qx) − u·h.
        let lin = |u: Vector2<f64>| -> (f64, f64, f64) { (u.dot(&q), sign * cross(u, q), -u.dot(&h)) };
        // |p|² = |q|² + |h|² − 2 h·R q.
        let (hc, hs, _) = lin(h);
        let qq = q.norm_squared() + h.norm_squared();
        let [elo, ehi] = w.edges;
        // cross(e, p) = (n·p) with n = (−e.y, e.x); cross(p, e) = (−n)·p.
        let nlo = Vector2::new(-elo.y, elo.x);
        let nhi = Vector2::new(ehi.y, -ehi.x);
        let cons = [
            // l_max² − |p|² ≥ 0
            (2.0 * hc, 2.0 * hs, w.l_max * w.l_max - qq),
            // |p|² − l_min² ≥ 0
            (-2.0 * hc, -2.0 * hs, qq - w.l_min * w.l_min),
            lin(nlo),
            lin(nhi),
        ];
        for (a, b, c) in cons {
            t_max = t_max.min(exit_sinusoid(a, b, c, t_max));
        }
    }
    t_max
}

/// The largest translation of the body along y_r in the direction `sign` (+1 forward, −1
/// back), at most `limit`, that keeps every foot in its workspace along the whole motion and
/// the centre of gravity inside the four feet's hull by `margin`. Exact: the workspace
/// boundaries are quadratic or linear in the distance s, the hull's edges linear.
pub fn max_translation(model: &QuadrupedModel, margin: f64, state: &GaitState, sign: f64, limit: f64) -> f64 {
    let mut s_max = limit.max(0.0);
    for leg in 0..4 {
        // p(s) = p0 − σ s ŷ (the body moves forward, the planted foot moves back).
        let p = state.foot_from_hip(model, leg);
        let w = &model.workspaces[leg];
        let y = Vector2::new(0.0, -sign);
        // |p0 + s y|² = |p0|² + 2 s p0·y + s².
        let (pp, py) = (p.norm_squared(), p.dot(&y));
        s_max = s_max.min(exit_quadratic(-1.0, -2.0 * py, w.l_max * w.l_max - pp, s_max));
        s_max = s_max.min(exit_quadratic(1.0, 2.0 * py, pp - w.l_min * w.l_min, s_max));
        let [elo, ehi] = w.edges;
        // cross(e, p0 + s y) = cross(e, p0) + s cross(e, y).
        s_max = s_max.min(exit_quadratic(0.0, cross(elo, y), cross(elo, p), s_max));
        s_max = s_max.min(exit_quadratic(0.0, cross(y, ehi), cross(p, ehi), s_max));
    }
    // Stability on four feet: the centre c + s σ ŷ_r stays inside the hull by `margin`. The
    // hull's margin is concave along a line, so the set of s where it holds is an interval:
    // bisect its end (to 1e-12 [j]) when the end of the motion fails it.
    let dir = sign * state.body.forward();
    let need = margin.min(hull_margin(&state.feet, state.body.centre()));
    let ok = |s: f64| hull_margin(&state.feet, state.body.centre() + s * dir) >= need;
    if !ok(s_max) {
        let (mut lo, mut hi) = (0.0, s_max);
        while hi - lo > 1e-12 {
            let mid = 0.5 * (lo + hi);
            if ok(mid) {
                lo = mid
            } else {
                hi = mid
            }
        }
        s_max = lo;
    }
    s_max
}

/// sup{t ∈ [0, limit] : g ≥ min(0, g(0)) on [0, t]} for g(t) = a cos t + b sin t + c.
fn exit_sinusoid(a: f64, b: f64, c: f64, limit: f64) -> f64 {
    let g = |t: f64| a * t.cos() + b * t.sin() + c;
    let tau = g(0.0).min(0.0);
    // g − τ = M cos(t − δ) + c − τ.
    let m = a.hypot(b);
    let mut roots = Roots::default();
    if m > 1e-15 {
        let k = (tau - c) / m;
        if (-1.0..=1.0).contains(&k) {
            let d = b.atan2(a);
            let r = k.acos();
            for base in [d + r, d - r] {
                for n in -2..=2 {
                    let t = base + 2.0 * PI * n as f64;
                    if t > 0.0 && t < limit {
                        roots.push(t);
                    }
                }
            }
        }
    }
    first_exit(&g, tau, &mut roots, limit)
}

/// sup{s ∈ [0, limit] : g ≥ min(0, g(0)) on [0, s]} for g(s) = a s² + b s + c.
fn exit_quadratic(a: f64, b: f64, c: f64, limit: f64) -> f64 {
    let g = |s: f64| (a * s + b) * s + c;
    let tau = g(0.0).min(0.0);
    // Fast path, the common case: g ≥ τ at both ends, and a convex g's vertex inside, if any,
    // too (a linear or concave g is then ≥ τ throughout). The root search below would return
    // `limit` as well.
    if g(limit) >= tau {
        let vertex = if a > 0.0 { -b / (2.0 * a) } else { f64::NAN };
        if !(vertex > 0.0 && vertex < limit) || g(vertex) >= tau {
            return limit;
        }
    }
    let cc = c - tau;
    let mut roots = Roots::default();
    if a.abs() < 1e-15 {
        if b.abs() > 1e-15 {
            roots.push(-cc / b);
        }
    } else {
        let disc = b * b - 4.0 * a * cc;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            roots.push((-b + sq) / (2.0 * a));
            roots.push((-b - sq) / (2.0 * a));
        }
    }
    roots.keep_within(limit);
    first_exit(&g, tau, &mut roots, limit)
}

/// A few roots on the stack (at most 20: two families × five periods, and the limit).
#[derive(Default)]
struct Roots {
    t: [f64; 24],
    n: usize,
}

impl Roots {
    fn push(&mut self, t: f64) {
        if self.n < self.t.len() {
            self.t[self.n] = t;
            self.n += 1;
        }
    }

    fn keep_within(&mut self, limit: f64) {
        let mut k = 0;
        for i in 0..self.n {
            let t = self.t[i];
            if t > 0.0 && t < limit {
                self.t[k] = t;
                k += 1;
            }
        }
        self.n = k;
    }
}

/// Between consecutive roots g − τ keeps its sign: the first interval whose midpoint is below
/// τ ends the motion at its start.
fn first_exit(g: &dyn Fn(f64) -> f64, tau: f64, roots: &mut Roots, limit: f64) -> f64 {
    roots.push(limit);
    let r = &mut roots.t[..roots.n];
    r.sort_unstable_by(f64::total_cmp);
    // Intervals shorter than 1e-12 are rounding noise around a root at the start; a dip of
    // 1e-12 below τ is within [`TOLERANCE`].
    let mut prev = 0.0;
    for &r in r.iter() {
        if r > prev + 1e-12 && g(0.5 * (prev + r)) < tau - 1e-12 {
            return prev;
        }
        prev = f64::max(prev, r);
    }
    limit
}

/// a × b (z component).
pub fn cross(a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// The unit vector at angle `a`.
pub fn unit(a: f64) -> Vector2<f64> {
    Vector2::new(a.cos(), a.sin())
}

/// `v` rotated by `a` counter-clockwise.
pub fn rotate(v: Vector2<f64>, a: f64) -> Vector2<f64> {
    let (s, c) = a.sin_cos();
    Vector2::new(c * v.x - s * v.y, s * v.x + c * v.y)
}

/// Maps an angle to (−π, π].
pub fn wrap(a: f64) -> f64 {
    let mut w = a.rem_euclid(2.0 * PI);
    if w > PI {
        w -= 2.0 * PI;
    }
    w
}
