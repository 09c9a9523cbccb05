//! The obstacle model λ = {p, r, R, σ} (eq. 4) and the potential V(d) (eq. 16) of the VFO
//! paper, with its derivative V'(d).

use nalgebra::Point2;

use crate::error::{check_coordinates, positive_finite, PlannerError};

/// One obstacle as the VFO law sees it: centre p, forbidden radius r = r_p + r_r (obstacle plus
/// robot radius) and influence radius R > r. Its decision σ lives beside it, in a list of
/// [`Sigma`] with the same indices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Obstacle {
    centre: Point2<f64>,
    forbidden_radius: f64,
    influence_radius: f64,
}

impl Obstacle {
    /// An obstacle at `centre` with forbidden radius `forbidden_radius` (r, finite, > 0) and
    /// influence radius `influence_radius` (R, finite, > r).
    pub fn new(centre: Point2<f64>, forbidden_radius: f64, influence_radius: f64) -> Result<Self, PlannerError> {
        check_coordinates("obstacle centre", centre.x, centre.y, 0.0)?;
        positive_finite("forbidden_radius", forbidden_radius)?;
        positive_finite("influence_radius", influence_radius)?;
        if influence_radius <= forbidden_radius {
            return Err(PlannerError::InvalidConfig {
                name: "influence_radius",
                value: influence_radius,
                reason: "must exceed the forbidden radius r",
            });
        }
        Ok(Obstacle {
            centre,
            forbidden_radius,
            influence_radius,
        })
    }

    /// The centre p.
    pub fn centre(&self) -> Point2<f64> {
        self.centre
    }

    /// r = r_p + r_r (m): the robot's centre inside this circle is a collision.
    pub fn forbidden_radius(&self) -> f64 {
        self.forbidden_radius
    }

    /// R (m): the influence zone, where V(d) > 0.
    pub fn influence_radius(&self) -> f64 {
        self.influence_radius
    }

    /// d = ‖p − q*‖ (eq. 17).
    pub fn distance(&self, point: &Point2<f64>) -> f64 {
        (self.centre - point).norm()
    }

    /// V(d) of this obstacle at `point` (eq. 16).
    pub fn potential_at(&self, point: &Point2<f64>) -> f64 {
        potential(self.distance(point), self.forbidden_radius, self.influence_radius)
    }
}

/// Potential V(d), eq. (16) of the VFO paper: 0 for d > R, ((d² − R²)/(d² − r²))² for
/// r < d ≤ R, +∞ for d ≤ r (a collision).
pub fn potential(d: f64, r: f64, big_r: f64) -> f64 {
    if d > big_r {
        0.0
    } else if d > r {
        let q = (d * d - big_r * big_r) / (d * d - r * r);
        q * q
    } else {
        f64::INFINITY
    }
}

/// V'(d) = 4d(R² − r²)(d² − R²)/(d² − r²)³ for r < d ≤ R, 0 beyond R (SPEC §5); −∞ for d ≤ r.
/// It is ≤ 0: V falls as the robot moves away, and is continuous at R (V'(R) = 0).
pub fn potential_derivative(d: f64, r: f64, big_r: f64) -> f64 {
    if d > big_r {
        0.0
    } else if d > r {
        let b = d * d - r * r;
        4.0 * d * (big_r * big_r - r * r) * (d * d - big_r * big_r) / (b * b * b)
    } else {
        f64::NEG_INFINITY
    }
}

/// The decision σ for one obstacle (eq. 7): undecided, +1 (pass it on the right as seen from
/// the robot) or −1 (on the left). The order (undecided < right < left) is the tie rule's
/// lexicographic order: +1 is the branch the paper follows first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub enum Sigma {
    /// Not decided yet ("?" in the paper's Fig. 3).
    #[default]
    Undecided,
    /// σ = +1: pass the obstacle on the right.
    Right,
    /// σ = −1: pass the obstacle on the left.
    Left,
}

impl Sigma {
    /// σ as a number in h*_o (eq. 7). An undecided σ counts as +1: the optimiser never lets a
    /// virtual robot be inside a zone whose σ is undecided (it decides at the entry), and the
    /// follower re-optimises when the real robot enters one (it passes on the right meanwhile).
    pub fn value(self) -> f64 {
        match self {
            Sigma::Undecided | Sigma::Right => 1.0,
            Sigma::Left => -1.0,
        }
    }

    /// The paper's notation: `?`, `+1`, `-1`.
    pub fn as_str(self) -> &'static str {
        match self {
            Sigma::Undecided => "?",
            Sigma::Right => "+1",
            Sigma::Left => "-1",
        }
    }
}
