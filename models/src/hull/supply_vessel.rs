//! 3-DOF low-frequency DP model of the supply vessel *Northern Clipper* [Fossen1999].
//!
//! # Source
//! [Fossen1999]:
//! * kinematics η̇ = J(ψ) ν [Fossen1999, sec. 2.1, eqs. (1)-(2)] (η = [x, y, ψ], ν = [u, v, r]);
//! * LF model M ν̇ + D ν = τ + Jᵀ(ψ) b [Fossen1999, sec. 2.2, eqs. (3)-(6)];
//! * bias model (earth-fixed b) [Fossen1999, sec. 2.3, eq. (7)] — here an *input* (the
//!   `Current`/`Wind` models or a constant supply it);
//! * the wave-frequency motion η_w [Fossen1999, sec. 2.4-2.5] is superposed on the measurement,
//!   y = η + η_w, not fed through the hull;
//! * Northern Clipper M and D [Fossen1999, eqs. (56)-(57)] (SI, x_G = 0, u₀ = 0) and the
//!   [DERIVED] eig(M⁻¹D) = 0.11907, 0.025655, 0.0094579 1/s.
//!
//! # Readings taken
//! * M and D are taken as dimensional SI (kg, kg·m², N·s/m, …); the paper prints no units.
//! * τ = B_u u with B_u not given: the input is τ itself (surge force, sway force, yaw moment),
//!   as in the paper's simulation [Fossen1999, eq. (61)].
//! * b is earth-fixed [N, N, N·m] and rotated into the body by Jᵀ(ψ) [Fossen1999, eq. (3)].
//! * No separate current velocity input: the paper lumps current into b.
//!
//! # Integration
//! RK4 with a fixed sub-step ≤ [`SupplyVessel::max_substep`] (default 0.1 s; the fastest open-loop
//! time constant is 8.40 s), inputs held over the step; see [`crate::integrate`].

use super::wrap_pi;
use crate::error::{check_finite, check_positive, require, ParamError};
use crate::integrate::rk4_advance;
use crate::math::sin_cos;
use crate::memo::{bits, Bits, Memo};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Inputs, held over a step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SupplyVesselInputs {
    /// Thrust τ = [surge force N, sway force N, yaw moment N·m] (body frame).
    pub tau: [f64; 3],
    /// Earth-fixed bias b = [north force N, east force N, yaw moment N·m] [Fossen1999, eq. (3)].
    pub bias: [f64; 3],
    /// Wave-frequency motion η_w = [north m, east m, yaw rad] superposed on the measurement.
    pub wave_motion: [f64; 3],
}

/// Outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SupplyVesselOutputs {
    pub time: f64,
    /// LF position and heading η = [x north m, y east m, ψ rad] (ψ continuous).
    pub eta: [f64; 3],
    pub heading_wrapped: f64,
    /// LF body velocity ν = [u m/s, v m/s, r rad/s].
    pub nu: [f64; 3],
    /// Measured position/heading y = η + η_w (from the last step's wave input).
    pub measured: [f64; 3],
}

/// The vessel. State `[x, y, ψ, u, v, r]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SupplyVessel {
    /// Inertia matrix M [Fossen1999, eq. (5)], row-major.
    pub m: [[f64; 3]; 3],
    /// Damping matrix D [Fossen1999, eq. (6)], row-major.
    pub d: [[f64; 3]; 3],
    /// Largest RK4 sub-step [s].
    pub max_substep: f64,
    state: [f64; 6],
    wave_motion: [f64; 3],
    time: f64,
    /// M⁻¹ of the last step's M (derived, see [`crate::memo`]).
    #[serde(skip)]
    m_inverse: Memo<Bits<9>, Matrix3<f64>>,
}

/// Northern Clipper M [Fossen1999, eq. (56)].
pub const NORTHERN_CLIPPER_M: [[f64; 3]; 3] = [
    [5.3122e6, 0.0, 0.0],
    [0.0, 8.2831e6, 0.0],
    [0.0, 0.0, 3.7454e9],
];
/// Northern Clipper D [Fossen1999, eq. (57)].
pub const NORTHERN_CLIPPER_D: [[f64; 3]; 3] = [
    [5.0242e4, 0.0, 0.0],
    [0.0, 2.7229e5, -4.3933e6],
    [0.0, -4.3933e6, 4.1894e8],
];

impl SupplyVessel {
    /// A vessel at rest at the origin, heading north. M must be invertible, all entries finite.
    pub fn new(m: [[f64; 3]; 3], d: [[f64; 3]; 3]) -> Result<Self, ParamError> {
        const MN: [[&str; 3]; 3] = [
            ["m11", "m12", "m13"],
            ["m21", "m22", "m23"],
            ["m31", "m32", "m33"],
        ];
        const DN: [[&str; 3]; 3] = [
            ["d11", "d12", "d13"],
            ["d21", "d22", "d23"],
            ["d31", "d32", "d33"],
        ];
        for i in 0..3 {
            for j in 0..3 {
                check_finite(MN[i][j], m[i][j])?;
                check_finite(DN[i][j], d[i][j])?;
            }
            check_positive(MN[i][i], m[i][i])?;
        }
        let mm = Matrix3::from_fn(|i, j| m[i][j]);
        require(
            mm.try_inverse().is_some(),
            "m (determinant)",
            mm.determinant(),
            "must be invertible",
        )?;
        Ok(SupplyVessel {
            m,
            d,
            max_substep: 0.1,
            state: [0.0; 6],
            wave_motion: [0.0; 3],
            time: 0.0,
            m_inverse: Memo::default(),
        })
    }

    /// Northern Clipper [Fossen1999, eqs. (56)-(57)].
    pub fn northern_clipper() -> Self {
        Self::new(NORTHERN_CLIPPER_M, NORTHERN_CLIPPER_D).expect("valid preset")
    }

    /// State `[x, y, ψ, u, v, r]`.
    pub fn state(&self) -> &[f64; 6] {
        &self.state
    }

    /// Sets position/heading η and velocity ν.
    pub fn set_state(&mut self, eta: [f64; 3], nu: [f64; 3]) {
        self.state = [eta[0], eta[1], eta[2], nu[0], nu[1], nu[2]];
    }

    pub fn time(&self) -> f64 {
        self.time
    }

    /// Advances exactly `h` seconds (RK4, sub-step ≤ `max_substep`), inputs held.
    pub fn step(&mut self, inputs: &SupplyVesselInputs, h: f64) {
        let m = self.m;
        let key = bits(std::array::from_fn(|k| m[k / 3][k % 3]));
        let minv = *self.m_inverse.get(key, || {
            Matrix3::from_fn(|i, j| m[i][j])
                .try_inverse()
                .unwrap_or_else(Matrix3::zeros)
        });
        let dd = Matrix3::from_fn(|i, j| self.d[i][j]);
        let tau = Vector3::from(inputs.tau);
        let b = Vector3::from(inputs.bias);
        rk4_advance(&mut self.state, h, self.max_substep, |s| {
            let (sp, cp) = sin_cos(s[2]);
            let nu = Vector3::new(s[3], s[4], s[5]);
            // Jᵀ(ψ) b
            let bb = Vector3::new(cp * b[0] + sp * b[1], -sp * b[0] + cp * b[1], b[2]);
            let acc = minv * (tau + bb - dd * nu);
            [
                cp * s[3] - sp * s[4],
                sp * s[3] + cp * s[4],
                s[5],
                acc[0],
                acc[1],
                acc[2],
            ]
        });
        self.wave_motion = inputs.wave_motion;
        if h > 0.0 && h.is_finite() {
            self.time += h;
        }
    }

    /// Current outputs.
    pub fn outputs(&self) -> SupplyVesselOutputs {
        let s = &self.state;
        let w = &self.wave_motion;
        SupplyVesselOutputs {
            time: self.time,
            eta: [s[0], s[1], s[2]],
            heading_wrapped: wrap_pi(s[2]),
            nu: [s[3], s[4], s[5]],
            measured: [s[0] + w[0], s[1] + w[1], s[2] + w[2]],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::exp;

    /// [DERIVED] from [Fossen1999, eqs. (56)-(57)]: eig(M⁻¹D) = 0.11907, 0.025655, 0.0094579 1/s (relative 1e-4).
    #[test]
    fn open_loop_eigenvalues() {
        let m = Matrix3::from_fn(|i, j| NORTHERN_CLIPPER_M[i][j]);
        let d = Matrix3::from_fn(|i, j| NORTHERN_CLIPPER_D[i][j]);
        let a = m.try_inverse().unwrap() * d;
        let mut e: Vec<f64> = a.complex_eigenvalues().iter().map(|z| z.re).collect();
        e.sort_by(|x, y| y.partial_cmp(x).unwrap());
        println!("eig(M^-1 D) = {e:?}");
        for (x, y) in e.iter().zip([0.11907, 0.025655, 0.0094579]) {
            assert!((x - y).abs() < 1e-4 * y, "{x} vs {y}");
        }
    }

    /// Free drift under a constant body force: the steady state is ν = D⁻¹τ, written out here
    /// in closed form: u = X/D11, and for the coupled sway-yaw block
    /// v = (D33 Y − D23 N)/Δ, r = (D22 N − D32 Y)/Δ, Δ = D22 D33 − D23 D32 (ν is independent
    /// of ψ because τ acts in the body frame and b = 0). Simulated for 3000 s (28 slowest time
    /// constants); tolerance 1e-9 relative. Also the surge transient
    /// u(t) = (X/D11)(1 − e^{−t D11/M11}) at t = 20 s (1e-9 relative).
    #[test]
    fn free_drift_steady_state() {
        let (x, y, n) = (1.0e4, 2.0e4, 3.0e5);
        let mut s = SupplyVessel::northern_clipper();
        let inp = SupplyVesselInputs {
            tau: [x, y, n],
            ..Default::default()
        };
        let (d11, d22, d23, d32, d33, m11) =
            (5.0242e4, 2.7229e5, -4.3933e6, -4.3933e6, 4.1894e8, 5.3122e6);
        s.step(&inp, 20.0);
        let u20 = x / d11 * (1.0 - exp(-20.0 * d11 / m11));
        assert!((s.outputs().nu[0] - u20).abs() < 1e-9 * u20);
        for _ in 0..2980 {
            s.step(&inp, 1.0);
        }
        let o = s.outputs();
        let det = d22 * d33 - d23 * d32;
        let v = (d33 * y - d23 * n) / det;
        let r = (d22 * n - d32 * y) / det;
        println!(
            "free drift: nu = {:?}, closed form u = {}, v = {v}, r = {r}",
            o.nu,
            x / d11
        );
        assert!((o.nu[0] - x / d11).abs() < 1e-9 * (x / d11));
        assert!((o.nu[1] - v).abs() < 1e-9 * v.abs());
        assert!((o.nu[2] - r).abs() < 1e-9 * r.abs());
    }

    /// Earth-fixed bias: b = [b_N, 0, 0] at ψ = 0 drives the vessel north at the steady speed
    /// b_N/D11 with no sway or yaw; with the heading east the same b acts as a body sway force
    /// −b_N (Jᵀ(π/2) b = [0, −b_N, 0], [Fossen1999, eq. (3)]), checked on the initial sway acceleration −b_N/M22.
    /// The measured output is η + η_w.
    #[test]
    fn earth_fixed_bias_and_wave_superposition() {
        let bn = 5.0e3;
        let mut s = SupplyVessel::northern_clipper();
        let inp = SupplyVesselInputs {
            bias: [bn, 0.0, 0.0],
            wave_motion: [1.0, -2.0, 0.01],
            ..Default::default()
        };
        for _ in 0..3000 {
            s.step(&inp, 1.0);
        }
        let o = s.outputs();
        assert!((o.nu[0] - bn / 5.0242e4).abs() < 1e-9 * bn / 5.0242e4);
        assert!(o.nu[1].abs() < 1e-12 && o.nu[2].abs() < 1e-15 && o.eta[2].abs() < 1e-15);
        assert_eq!(o.measured, [o.eta[0] + 1.0, o.eta[1] - 2.0, 0.01]);
        // Heading east: the north bias is a body force −b_N in sway (Jᵀ(π/2) b = [0, −b_N, 0]).
        let mut s = SupplyVessel::northern_clipper();
        s.set_state([0.0, 0.0, std::f64::consts::FRAC_PI_2], [0.0; 3]);
        let inp = SupplyVesselInputs {
            bias: [bn, 0.0, 0.0],
            ..Default::default()
        };
        s.step(&inp, 0.01);
        // initial acceleration in sway = −b_N/M22 (over 0.01 s: v ≈ −0.01 b_N/M22)
        let o = s.outputs();
        let v_exp = -0.01 * bn / 8.2831e6;
        assert!(
            (o.nu[1] - v_exp).abs() < 1e-3 * v_exp.abs(),
            "{} vs {v_exp}",
            o.nu[1]
        );
    }

    #[test]
    fn rejects_bad_parameters() {
        let mut m = NORTHERN_CLIPPER_M;
        m[2][2] = f64::NAN;
        assert_eq!(
            SupplyVessel::new(m, NORTHERN_CLIPPER_D).unwrap_err().name,
            "m33"
        );
    }
}
