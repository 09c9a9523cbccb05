//! Path quality over a segment (eq. 14–22 of the VFO paper): the running indices χ_D, χ_B,
//! χ_E, χ_S, their merge over the pieces of a path, the normalisation over the candidates and
//! the score Ψ_z.

/// The running indices X = {χ_D, χ_B, χ_E, χ_S} of one path (eq. 14, 15, 18, 19).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PathIndices {
    /// χ_D (m): path length, Σ ‖q̇*‖·T_p (eq. 14).
    pub length: f64,
    /// χ_B: danger, the largest Σ_k V(d_k) met (eq. 15).
    pub danger: f64,
    /// χ_E: control cost, Σ ‖u‖·T_p with u = [ω, v] (eq. 18; rad and m mixed as in the paper).
    pub control: f64,
    /// χ_S (rad/s): smoothness, the largest |θ̇| = |ω| (eq. 19).
    pub smoothness: f64,
}

impl PathIndices {
    /// One sampling period T_p = `dt` with command (v, ω), ending where Σ V(d_k) = `danger`.
    pub fn accumulate(&mut self, v: f64, omega: f64, danger: f64, dt: f64) {
        self.length += v.abs() * dt;
        self.danger = self.danger.max(danger);
        self.control += v.hypot(omega) * dt;
        self.smoothness = self.smoothness.max(omega.abs());
    }

    /// merge(X1, X2): `next` continues `self` — lengths and costs add, danger and smoothness
    /// take the maximum — so merged pieces equal one uninterrupted run (SPEC §5).
    pub fn merge(&self, next: &PathIndices) -> PathIndices {
        PathIndices {
            length: self.length + next.length,
            danger: self.danger.max(next.danger),
            control: self.control + next.control,
            smoothness: self.smoothness.max(next.smoothness),
        }
    }

    /// The four indices in the order D, B, E, S.
    pub fn as_array(&self) -> [f64; 4] {
        [self.length, self.danger, self.control, self.smoothness]
    }
}

/// The weights K_D, K_B, K_E, K_S of Ψ_z (eq. 22), each in [0, ∞).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QualityWeights {
    /// K_D, on length.
    pub length: f64,
    /// K_B, on danger.
    pub danger: f64,
    /// K_E, on control cost.
    pub control: f64,
    /// K_S, on smoothness.
    pub smoothness: f64,
}

impl Default for QualityWeights {
    /// The paper's starting point {K_B = 2, K_E = 1, K_D = 1, K_S = 1} (K_B ≥ 2·max of the
    /// others keeps paths safe).
    fn default() -> Self {
        QualityWeights {
            length: 1.0,
            danger: 2.0,
            control: 1.0,
            smoothness: 1.0,
        }
    }
}

impl QualityWeights {
    /// Checks every weight: finite and ≥ 0.
    pub fn validate(&self) -> Result<(), crate::PlannerError> {
        for (name, value) in [
            ("k_d", self.length),
            ("k_b", self.danger),
            ("k_e", self.control),
            ("k_s", self.smoothness),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(crate::PlannerError::InvalidConfig {
                    name,
                    value,
                    reason: "a weight must be finite and non-negative",
                });
            }
        }
        Ok(())
    }

    fn as_array(&self) -> [f64; 4] {
        [self.length, self.danger, self.control, self.smoothness]
    }
}

/// Ψ = 0 if χ_max = 0, else 1 − χ/χ_max (eq. 20), with χ_max over `all` (eq. 21).
pub fn normalise(chi: f64, chi_max: f64) -> f64 {
    if chi_max > 0.0 {
        1.0 - chi / chi_max
    } else {
        0.0
    }
}

/// The normalised indices [Ψ_D, Ψ_B, Ψ_E, Ψ_S] of every candidate (eq. 20–21).
pub fn normalised(candidates: &[PathIndices]) -> Vec<[f64; 4]> {
    let mut max = [0.0f64; 4];
    for c in candidates {
        for (m, x) in max.iter_mut().zip(c.as_array()) {
            *m = m.max(x);
        }
    }
    candidates
        .iter()
        .map(|c| {
            let x = c.as_array();
            [
                normalise(x[0], max[0]),
                normalise(x[1], max[1]),
                normalise(x[2], max[2]),
                normalise(x[3], max[3]),
            ]
        })
        .collect()
}

/// Ψ_z = K_D·Ψ_D + K_B·Ψ_B + K_E·Ψ_E + K_S·Ψ_S (eq. 22) of normalised indices.
pub fn path_score(psi: &[f64; 4], weights: &QualityWeights) -> f64 {
    psi.iter().zip(weights.as_array()).map(|(p, k)| p * k).sum()
}
