//! The comparison peer (Nav2 Jazzy's graceful docking law, `benches/common/graceful.rs`) against
//! hand-worked values of the C++ formulas, so the comparison measures the real law.

#[path = "../benches/common/graceful.rs"]
mod graceful;

use approx::assert_relative_eq;
use graceful::{ego_polar, Graceful};
use mobil_geom::Pose2;

#[test]
fn straight_ahead_runs_at_v_max_without_turning() {
    // Target (1, 0, 0) from the origin: r = 1, φ = δ = 0, κ = 0 → v = 0.25 / (1 + 0) = 0.25,
    // min(0.25·1/0.25, 0.25) = 0.25; ω = 0.
    let g = Graceful::default();
    assert_eq!(g.velocity(&Pose2::new(1.0, 0.0, 0.0), &Pose2::identity()), (0.25, 0.0));
}

#[test]
fn oblique_target_by_hand() {
    // Target (1, 1, 0) from the origin: line of sight atan2(−1, 1) = −π/4, r = √2,
    // φ = 0 − π/4, δ = 0 − π/4.
    // κ = −1/√2·(2·(−π/4 − atan(3π/4)) + (1 + 3/(1 + (3π/4)²))·sin(−π/4))
    //   = −0.707107·(2·(−0.785398 − 1.169422) + 1.457900·(−0.707107))
    //   = −0.707107·(−3.909640 − 1.030893) = 3.493480;
    // v = 0.25 / (1 + 0.4·3.493480²) = 0.042504, below v_min → 0.1; ω = κ·v = 0.349348.
    let g = Graceful::default();
    let target = Pose2::new(1.0, 1.0, 0.0);
    let (r, phi, delta) = ego_polar(&target, &Pose2::identity());
    assert_relative_eq!(r, 2f64.sqrt(), epsilon = 1e-12);
    assert_relative_eq!(phi, -std::f64::consts::FRAC_PI_4, epsilon = 1e-12);
    assert_relative_eq!(delta, -std::f64::consts::FRAC_PI_4, epsilon = 1e-12);
    assert_relative_eq!(g.curvature(r, phi, delta), 3.493_480, epsilon = 1e-5);
    let (v, w) = g.velocity(&target, &Pose2::identity());
    assert_eq!(v, 0.1);
    assert_relative_eq!(w, 0.349_348, epsilon = 1e-5);
    // The target lies 0.25 m beyond the dock along its heading; docked within 0.05 m.
    let dock = Pose2::new(2.0, 1.0, std::f64::consts::FRAC_PI_2);
    let t = g.target(&dock);
    assert_relative_eq!(t.x, 2.0, epsilon = 1e-12);
    assert_relative_eq!(t.y, 1.25, epsilon = 1e-12);
    assert!(g.is_docked(&dock, &Pose2::new(2.03, 1.03, 0.0)));
    assert!(!g.is_docked(&dock, &Pose2::new(2.04, 1.04, 0.0)));
}
