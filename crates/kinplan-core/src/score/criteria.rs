//! The S0 criteria by name, the scores of one trajectory, and the per-step
//! orientation and displacement terms (S0 eq. 2.1–2.5).

use std::fmt;

use nalgebra::{Point3, UnitQuaternion};

/// A named trajectory criterion (S0 §2, S2 §3.3). `name()` gives the key the
/// service and the Python client use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Criterion {
    /// Cartesian distance of the tool, m (S0 eq. 2.1).
    Cd,
    /// Joint distance, rad (m for prismatic joints) (S0 eq. 2.2).
    Jd,
    /// Orientation change as printed: Σ acos|⟨q_i, q_{i−1}⟩|, half the
    /// rotation angles, rad (S0 eq. 2.3).
    Oc,
    /// Geodesic orientation change: Σ 2·acos|⟨q_i, q_{i−1}⟩|, rad.
    OcGeodesic,
    /// Control pseudo-cost: weighted joint distance (S0 eq. 2.4).
    Cpc,
    /// Robot displacement metric, m (S0 eq. 2.5).
    Rdm,
    /// Joint pseudo-jerk, rad (S0 eq. 2.6).
    Jj,
    /// Cartesian pseudo-jerk, m (S0 eq. 2.7).
    Cj,
    /// Joint maximum pseudo-jerk, rad (S0 eq. 2.8).
    Jmj,
    /// Cartesian maximum pseudo-jerk, m (S0 eq. 2.9).
    Cmj,
    /// Joint jerk peaks: summed predicted slowdown (S0 eq. 2.13).
    Jjp,
    /// Cartesian jerk peaks: summed predicted slowdown (S0 eq. 2.14).
    Cjp,
    /// Synchronized PTP cycle time, s (S2 §3.3).
    CycleTime,
}

impl Criterion {
    /// Every criterion, in the order of S0 §2 then the cycle time.
    pub const ALL: [Criterion; 13] = [
        Criterion::Cd,
        Criterion::Jd,
        Criterion::Oc,
        Criterion::OcGeodesic,
        Criterion::Cpc,
        Criterion::Rdm,
        Criterion::Jj,
        Criterion::Cj,
        Criterion::Jmj,
        Criterion::Cmj,
        Criterion::Jjp,
        Criterion::Cjp,
        Criterion::CycleTime,
    ];

    /// The key: "CD", "JD", "OC", "OC_geodesic", "CPC", "RDM", "JJ", "CJ",
    /// "JMJ", "CMJ", "JJP", "CJP", "cycle_time".
    pub fn name(self) -> &'static str {
        match self {
            Criterion::Cd => "CD",
            Criterion::Jd => "JD",
            Criterion::Oc => "OC",
            Criterion::OcGeodesic => "OC_geodesic",
            Criterion::Cpc => "CPC",
            Criterion::Rdm => "RDM",
            Criterion::Jj => "JJ",
            Criterion::Cj => "CJ",
            Criterion::Jmj => "JMJ",
            Criterion::Cmj => "CMJ",
            Criterion::Jjp => "JJP",
            Criterion::Cjp => "CJP",
            Criterion::CycleTime => "cycle_time",
        }
    }

    /// The criterion with this key (exact spelling of [`Criterion::name`]).
    ///
    /// ```
    /// use kinplan_core::score::Criterion;
    /// assert_eq!(Criterion::from_name("OC_geodesic"), Some(Criterion::OcGeodesic));
    /// assert_eq!(Criterion::from_name("oc"), None);
    /// ```
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }

    /// Unit of the value ("rad" for joint criteria stands for "rad or m" on
    /// prismatic joints; "1" is dimensionless).
    pub fn unit(self) -> &'static str {
        match self {
            Criterion::Cd | Criterion::Rdm | Criterion::Cj | Criterion::Cmj => "m",
            Criterion::Jd | Criterion::Oc | Criterion::OcGeodesic | Criterion::Jj | Criterion::Jmj => "rad",
            Criterion::Cpc => "weight·rad",
            Criterion::Jjp | Criterion::Cjp => "1",
            Criterion::CycleTime => "s",
        }
    }
}

impl fmt::Display for Criterion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Jerk with timestamps: the S0 pseudo-jerk sums with `Δ³` replaced by the
/// third time derivative estimate of [`super::third_derivative`]
/// (rad/s³, m/s³). Not one of the named criteria.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TimeScaledJerk {
    /// Σ_i Σ_j |q⃛_{i,j}|, rad/s³.
    pub jj: f64,
    /// Σ_i ‖p⃛_i‖, m/s³.
    pub cj: f64,
    /// max_i Σ_j |q⃛_{i,j}|, rad/s³.
    pub jmj: f64,
    /// max_i ‖p⃛_i‖, m/s³.
    pub cmj: f64,
}

/// All criteria of one trajectory (see [`Criterion`] for units and sources).
///
/// Short trajectories: with `n < 2` every distance (CD, JD, OC, OC_geodesic,
/// CPC, RDM) is 0; with `n < 4` there is no third difference, so JJ, CJ, JMJ,
/// CMJ, JJP and CJP are 0 and there are no peaks.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Scores {
    /// Number of waypoints `n`.
    pub waypoints: usize,
    /// CD, m.
    pub cd: f64,
    /// JD, rad.
    pub jd: f64,
    /// OC as printed (half angles), rad.
    pub oc: f64,
    /// OC as geodesic angles (`2·oc`), rad.
    pub oc_geodesic: f64,
    /// CPC.
    pub cpc: f64,
    /// RDM, m; `None` without robot points.
    pub rdm: Option<f64>,
    /// JJ, rad.
    pub jj: f64,
    /// CJ, m.
    pub cj: f64,
    /// JMJ, rad.
    pub jmj: f64,
    /// CMJ, m.
    pub cmj: f64,
    /// JJP (sum of predicted joint slowdowns over the peaks).
    pub jjp: f64,
    /// CJP (sum of predicted Cartesian slowdowns over the peaks).
    pub cjp: f64,
    /// Number of joint pseudo-jerk peaks counted in JJP.
    pub joint_peak_count: usize,
    /// Number of Cartesian pseudo-jerk peaks counted in CJP.
    pub cartesian_peak_count: usize,
    /// PTP cycle time, s; `None` without joint limits.
    pub cycle_time: Option<f64>,
    /// Time-scaled jerk; `None` without timestamps.
    pub time_scaled: Option<TimeScaledJerk>,
}

impl Scores {
    /// The value of criterion `c` (`None` for RDM without points and the
    /// cycle time without limits).
    pub fn get(&self, c: Criterion) -> Option<f64> {
        Some(match c {
            Criterion::Cd => self.cd,
            Criterion::Jd => self.jd,
            Criterion::Oc => self.oc,
            Criterion::OcGeodesic => self.oc_geodesic,
            Criterion::Cpc => self.cpc,
            Criterion::Rdm => return self.rdm,
            Criterion::Jj => self.jj,
            Criterion::Cj => self.cj,
            Criterion::Jmj => self.jmj,
            Criterion::Cmj => self.cmj,
            Criterion::Jjp => self.jjp,
            Criterion::Cjp => self.cjp,
            Criterion::CycleTime => return self.cycle_time,
        })
    }

    /// `(criterion, value)` for every criterion that has a value.
    pub fn iter(&self) -> impl Iterator<Item = (Criterion, f64)> + '_ {
        Criterion::ALL
            .into_iter()
            .filter_map(|c| self.get(c).map(|v| (c, v)))
    }
}

/// Orientation change of one step as S0 eq. 2.3 prints it, made sign-safe:
/// `acos(clamp(|⟨a, b⟩|, 0, 1))` — half the angle of the rotation taking `a`
/// to `b`, in `[0, π/2]` rad.
///
/// Why half: for unit quaternions `⟨a, b⟩ = cos(θ/2)` with `θ` the rotation
/// angle of `a⁻¹b`. Why `|·|`: `q` and `−q` are the same orientation, so the
/// printed `acos⟨a, b⟩` would depend on which sign the quaternion source picked
/// (an unchanged orientation could score π). It is evaluated as
/// `atan2(‖vec(a*·b)‖, |w(a*·b)|)` (`w(a*·b) = ⟨a, b⟩` exactly), which equals
/// the acos form and keeps full precision for small steps, where `acos` near 1
/// loses about half the digits.
///
/// ```
/// use kinplan_core::score::orientation_half_angle;
/// use nalgebra::{UnitQuaternion, Vector3};
/// let a = UnitQuaternion::identity();
/// let b = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.5);
/// assert!((orientation_half_angle(&a, &b) - 0.25).abs() < 1e-15);
/// let minus_b = UnitQuaternion::new_unchecked(-b.into_inner());
/// assert!((orientation_half_angle(&a, &minus_b) - 0.25).abs() < 1e-15);
/// ```
#[inline]
pub fn orientation_half_angle(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> f64 {
    let r = a.quaternion().conjugate() * b.quaternion();
    r.imag().norm().atan2(r.w.abs())
}

/// Geodesic angle between two orientations, `2·acos(|⟨a, b⟩|)` ∈ `[0, π]` rad:
/// the angle of the rotation `a⁻¹b` (OC_geodesic's step).
///
/// ```
/// use kinplan_core::score::orientation_geodesic_angle;
/// use nalgebra::{UnitQuaternion, Vector3};
/// let a = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.1);
/// let b = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.4);
/// assert!((orientation_geodesic_angle(&a, &b) - 0.3).abs() < 1e-15);
/// ```
#[inline]
pub fn orientation_geodesic_angle(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> f64 {
    2.0 * orientation_half_angle(a, b)
}

/// RDM's step: `max_{a∈A} ‖a(q_i) − a(q_{i−1})‖` over paired points (S0 eq. 2.5),
/// metres; 0 without points. Points are zipped: the shorter slice decides.
///
/// ```
/// use kinplan_core::score::max_point_displacement;
/// use nalgebra::Point3;
/// let before = [Point3::origin(), Point3::new(1.0, 0.0, 0.0)];
/// let after = [Point3::new(0.0, 0.1, 0.0), Point3::new(1.0, 0.0, 0.5)];
/// assert_eq!(max_point_displacement(&before, &after), 0.5);
/// ```
#[inline]
pub fn max_point_displacement(before: &[Point3<f64>], after: &[Point3<f64>]) -> f64 {
    before
        .iter()
        .zip(after)
        .map(|(a, b)| (b - a).norm_squared())
        .fold(0.0, f64::max)
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn names_round_trip() {
        for c in Criterion::ALL {
            assert_eq!(Criterion::from_name(c.name()), Some(c));
            assert_eq!(c.to_string(), c.name());
        }
    }

    #[test]
    fn half_angle_equals_printed_acos_form() {
        let axes = [Vector3::x_axis(), Vector3::y_axis(), Vector3::z_axis()];
        for (k, ax) in axes.iter().enumerate() {
            for i in 0..50 {
                let a = UnitQuaternion::from_axis_angle(ax, 0.37 * i as f64 + k as f64);
                let b = UnitQuaternion::from_euler_angles(0.1 * i as f64, -0.2, 0.05 * k as f64);
                let printed = a.coords.dot(&b.coords).abs().clamp(0.0, 1.0).acos();
                assert!((orientation_half_angle(&a, &b) - printed).abs() < 1e-7);
                assert!(orientation_half_angle(&a, &b) <= std::f64::consts::FRAC_PI_2);
            }
        }
    }

    #[test]
    fn tiny_rotation_keeps_precision() {
        let a = UnitQuaternion::identity();
        let b = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 2e-9);
        let h = orientation_half_angle(&a, &b);
        assert!((h - 1e-9).abs() < 1e-22, "{h}");
    }

    #[test]
    fn half_turn_is_half_pi() {
        let a = UnitQuaternion::identity();
        let b = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI);
        assert!((orientation_geodesic_angle(&a, &b) - std::f64::consts::PI).abs() < 1e-15);
    }

    #[test]
    fn displacement_of_no_points_is_zero() {
        assert_eq!(max_point_displacement(&[], &[]), 0.0);
    }

    #[test]
    fn scores_get_and_iter() {
        let s = Scores {
            cd: 1.0,
            rdm: None,
            cycle_time: Some(2.0),
            ..Default::default()
        };
        assert_eq!(s.get(Criterion::Cd), Some(1.0));
        assert_eq!(s.get(Criterion::Rdm), None);
        let keys: Vec<_> = s.iter().map(|(c, _)| c.name()).collect();
        assert_eq!(keys.len(), 12);
        assert!(keys.contains(&"cycle_time") && !keys.contains(&"RDM"));
    }
}
