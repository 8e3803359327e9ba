//! The closed-form solvers of the two 6R families by subproblem
//! decomposition, their configuration flags, and whole-turn enumeration.

use nalgebra::{Isometry3, Matrix3, Vector3};

use super::family::{AnalyticArm, Family};
use super::params::{AnalyticParams, Turns};
use super::subproblems::{Angles, AnglesCs, rot, rot_cs, sp1, sp1_cs, sp2, sp3_cs, sp4_cs, wrap};

/// Most whole-turn variants returned per joint with [`Turns::All`].
pub const MAX_TURNS: usize = 4;

/// How a controller names a solution: three booleans, each the side of a
/// singularity the arm is on (docs/inverse-kinematics.md#analytic).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct ConfigFlags {
    /// The wrist point lies behind axis 1: `(E₁⁻¹ w − p₁)·f < 0` with `f` the
    /// arm's forward direction at joint 1 = 0 (KUKA Status bit 0, "overhead").
    pub shoulder_back: bool,
    /// `sin(q₃ − q₃ˢ) < 0` with `q₃ˢ` the stretched-arm angle of joint 3.
    pub elbow_down: bool,
    /// `sin(q₅ − q₅ˢ) < 0` with `q₅ˢ` the wrist-singular angle of joint 5.
    pub wrist_flipped: bool,
}

/// One closed-form solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnalyticSolution {
    /// Joint values (rad), chain order, inside the limits.
    pub joints: [f64; 6],
    pub config: ConfigFlags,
    /// At a singular pose a joint could take any value; it was set to the
    /// seed's (or 0) and the set of solutions is a continuous family.
    pub singular: bool,
    /// Every subproblem held exactly; false only for the least-squares answers
    /// of [`AnalyticArm::nearest`].
    pub exact: bool,
}

/// The choice for a free angle: the seed's value, wrapped.
pub(super) fn pick(a: Angles, seed: f64) -> Angles {
    if a.free {
        Angles {
            angles: [wrap(seed), wrap(seed)],
            ..a
        }
    } else {
        a
    }
}

/// `(cos, sin)` of the reference angles of the elbow and wrist flags
/// (`q₃ˢ`, `q₅ˢ`): `sin(q − q_ref) = sin q cos q_ref − cos q sin q_ref`.
struct FlagRefs {
    q3: (f64, f64),
    q5: (f64, f64),
}

impl FlagRefs {
    /// `sin(q₃ − q₃ˢ) < 0` from `(cos q₃, sin q₃)`.
    fn elbow_down(&self, (c, s): (f64, f64)) -> bool {
        s * self.q3.0 - c * self.q3.1 < 0.0
    }

    /// `sin(q₅ − q₅ˢ) < 0` from `(cos q₅, sin q₅)`.
    fn wrist_flipped(&self, (c, s): (f64, f64)) -> bool {
        s * self.q5.0 - c * self.q5.1 < 0.0
    }
}

/// [`pick`] keeping each angle's cosine and sine.
fn pick_cs(a: AnglesCs, seed: f64) -> AnglesCs {
    if a.angles.free {
        AnglesCs::of(pick(a.angles, seed))
    } else {
        a
    }
}

/// Most base solutions of one pose: 8 for the closed-form families, 16 for a
/// general 6-joint arm (the degree of its characteristic polynomial).
const MAX_BASE: usize = 16;

/// Up to [`MAX_BASE`] base solutions (angles in (−π, π]).
pub(super) struct Base {
    pub(super) n: usize,
    pub(super) sols: [AnalyticSolution; MAX_BASE],
}

impl Base {
    pub(super) fn push(&mut self, joints: [f64; 6], config: ConfigFlags, singular: bool, exact: bool) {
        if self.n < MAX_BASE {
            self.sols[self.n] = AnalyticSolution {
                joints,
                config,
                singular,
                exact,
            };
            self.n += 1;
        }
    }
}

impl AnalyticArm {
    /// `E⁻¹ x = rot(hᵢ, −θ)(x − pᵢ) + pᵢ` given `rᵢ = rot(hᵢ, θ)`.
    #[inline]
    fn inv_apply(&self, i: usize, r: &Matrix3<f64>, x: &Vector3<f64>) -> Vector3<f64> {
        r.tr_mul(&(x - self.p[i])) + self.p[i]
    }

    /// The flags of a configuration whose wrist point with joint 1 undone,
    /// less `p₁`, is `y_minus_p1` (the same formulas as the solvers').
    fn flags(&self, y_minus_p1: &Vector3<f64>, q3: f64, q5: f64) -> ConfigFlags {
        let refs = self.flag_refs();
        let cs = |q: f64| {
            let (s, c) = q.sin_cos();
            (c, s)
        };
        ConfigFlags {
            shoulder_back: y_minus_p1.dot(&self.forward) < 0.0,
            elbow_down: refs.elbow_down(cs(q3)),
            wrist_flipped: refs.wrist_flipped(cs(q5)),
        }
    }

    /// The configuration flags of joint values `q` (6 values).
    ///
    /// ```
    /// use kinplan_core::ik::analytic::{AnalyticArm, AnalyticParams};
    /// let chain = kinplan_core::robot::builtin_chain("ur5").unwrap();
    /// let arm = AnalyticArm::new(&chain, 1e-9).unwrap();
    /// let q = [0.3, -1.2, 1.4, -0.8, 1.1, 0.2];
    /// let mut out = Vec::new();
    /// arm.solve_into(&chain.fk(&q), Some(&q), &AnalyticParams::default(), &mut out);
    /// let same = out.iter().find(|s| s.joints.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-9)).unwrap();
    /// assert_eq!(same.config, arm.config_of(&q));
    /// ```
    pub fn config_of(&self, q: &[f64]) -> ConfigFlags {
        let q: [f64; 6] = if self.reversed {
            std::array::from_fn(|i| q[5 - i])
        } else {
            std::array::from_fn(|i| q[i])
        };
        let last = match self.family {
            Family::SphericalWrist | Family::SphericalTwoIntersecting => 2,
            Family::ThreeParallel => 3,
            Family::Searched6R => return self.searched_config(&q),
        };
        let mut x = self.wrist;
        for i in (1..=last).rev() {
            x = rot(&self.h[i], q[i]) * (x - self.p[i]) + self.p[i];
        }
        self.flags(&(x - self.p[0]), q[2], q[4])
    }

    /// Every solution for tool pose `target` (base frame) inside the joint
    /// limits, written into `out` (cleared; no allocation once its capacity
    /// suffices): up to 8 configurations, each with its whole-turn variants
    /// ([`AnalyticParams::turns`]). Free joints of singular poses take the
    /// seed's value (0 without a seed). Unreachable poses give none (see
    /// [`AnalyticArm::nearest`]).
    ///
    /// Spherical wrist, with `G = T M⁻¹ = E₁⋯E₆` and wrist centre `w₀`:
    /// `w = G w₀ = E₁E₂E₃ w₀`; `q₁` by subproblem 4 from
    /// `h₂ᵀ E₁⁻¹ w = h₂ᵀ w₀` (axes 2, 3 parallel keep the `h₂` component);
    /// `q₃` by subproblem 3 from `‖E₃ w₀ − p₂‖ = ‖E₁⁻¹ w − p₂‖`; `q₂` by
    /// subproblem 1; then `R₃₆ = (R₁R₂R₃)ᵀ R_G = R₄R₅R₆`: `q₅` by subproblem 4
    /// from `h₄ᵀ R₅ h₆ = h₄ᵀ R₃₆ h₆`, `q₄` and `q₆` by subproblem 1.
    ///
    /// Three parallel (axes 2–4 parallel, 5 and 6 meeting at `w₀`): `q₁` by
    /// subproblem 4 from `h₂ᵀ E₁⁻¹ G w₀ = h₂ᵀ w₀`; `q₅` by subproblem 4 from
    /// `h₂ᵀ R₅ h₆ = (R₁h₂)ᵀ R_G h₆`; `q₆` by subproblem 1 from
    /// `R₆ (R_Gᵀ R₁ h₂) = R₅ᵀ h₂`; the sum `q₂ ± q₃ ± q₄` by subproblem 1 on
    /// `R₂₃₄ = R₁ᵀ R_G R₆ᵀ R₅ᵀ`; the point `y = E₁⁻¹ G E₆⁻¹ E₅⁻¹ p₄ = E₂E₃ p₄`
    /// gives `q₃` (subproblem 3) and `q₂` (subproblem 1). Source: Elias & Wen,
    /// IK-Geo (2025), the "spherical, two parallel" and "three parallel, two
    /// intersecting" decompositions; our own derivation and code.
    ///
    /// A reversed arm ([`AnalyticArm::is_reversed`]) solves `T⁻¹` for the chain
    /// read from the tool end and reverses each answer's joints.
    pub fn solve_into(
        &self,
        target: &Isometry3<f64>,
        seed: Option<&[f64]>,
        params: &AnalyticParams,
        out: &mut Vec<AnalyticSolution>,
    ) {
        out.clear();
        let base = self.base_in_order(
            target,
            seed,
            false,
            (params.solve_tolerance, f64::INFINITY, params.search_samples),
        );
        let base = &base.sols[..base.n];
        match params.turns {
            Turns::All => self.push_all_turns(base, out),
            Turns::NearestSeed => out.extend(base.iter().filter_map(|s| self.nearest_turn(s, seed))),
        }
    }

    /// The least-squares answers of every branch (exact or not), without limits
    /// or turns: for an unreachable pose, the candidates nearest to reaching it.
    pub fn nearest(
        &self,
        target: &Isometry3<f64>,
        seed: Option<&[f64]>,
        params: &AnalyticParams,
        out: &mut Vec<AnalyticSolution>,
    ) {
        out.clear();
        let base = self.base_in_order(
            target,
            seed,
            true,
            (params.solve_tolerance, f64::INFINITY, params.search_samples),
        );
        out.extend_from_slice(&base.sols[..base.n]);
    }

    /// The exact solutions of every configuration (angles in (−π, π], no
    /// limits or turns) that may lie nearer `seed` than `bound` (rad², each
    /// joint's difference taken over its nearest whole turn): on a
    /// spherical-shoulder arm a branch whose three arm joints alone already lie
    /// `bound` from the seed's is dropped before its wrist is solved (a lower
    /// bound, as the wrist's terms are not negative); other families return
    /// every exact branch.
    pub(crate) fn exact_near(
        &self,
        target: &Isometry3<f64>,
        seed: &[f64; 6],
        tol: f64,
        bound: f64,
        out: &mut Vec<AnalyticSolution>,
    ) {
        out.clear();
        let samples = AnalyticParams::default().search_samples;
        let base = self.base_in_order(target, Some(seed), false, (tol, bound, samples));
        out.extend_from_slice(&base.sols[..base.n]);
    }

    /// The base solutions in chain order (a reversed arm solves the inverse
    /// pose with the seed reversed, then reverses each answer).
    fn base_in_order(
        &self,
        target: &Isometry3<f64>,
        seed: Option<&[f64]>,
        keep_inexact: bool,
        (tol, bound, samples): (f64, f64, usize),
    ) -> Base {
        if !self.reversed {
            return self.base(target, seed, keep_inexact, (tol, bound, samples));
        }
        let rseed: Option<[f64; 6]> = seed
            .filter(|s| s.len() == 6)
            .map(|s| std::array::from_fn(|i| s[5 - i]));
        let mut base = self.base(
            &target.inverse(),
            rseed.as_ref().map(|s| &s[..]),
            keep_inexact,
            (tol, bound, samples),
        );
        for s in &mut base.sols[..base.n] {
            s.joints.reverse();
        }
        base
    }

    fn base(
        &self,
        target: &Isometry3<f64>,
        seed: Option<&[f64]>,
        keep_inexact: bool,
        (tol, bound, samples): (f64, f64, usize),
    ) -> Base {
        let g = target * self.m_inv;
        let seed = match seed {
            Some(s) if s.len() == 6 => [s[0], s[1], s[2], s[3], s[4], s[5]],
            _ => [0.0; 6],
        };
        let mut base = Base {
            n: 0,
            sols: [AnalyticSolution {
                joints: [0.0; 6],
                config: ConfigFlags::default(),
                singular: false,
                exact: true,
            }; MAX_BASE],
        };
        match self.family {
            Family::SphericalWrist => self.spherical(&g, &seed, keep_inexact, tol, &mut base),
            Family::ThreeParallel => self.three_parallel(&g, &seed, keep_inexact, tol, &mut base),
            Family::SphericalTwoIntersecting => {
                self.spherical_shoulder(&g, &seed, (keep_inexact, tol, bound), &mut base)
            }
            Family::Searched6R => self.searched_6r(&g, &seed, keep_inexact, tol, samples, &mut base),
        }
        base
    }

    /// Spherical wrist: see [`AnalyticArm::solve_into`]; rotations from the
    /// subproblems' cosines and sines as in [`Self::three_parallel`].
    fn spherical(&self, g: &Isometry3<f64>, seed: &[f64; 6], keep: bool, tol: f64, out: &mut Base) {
        let (h, p) = (&self.h, &self.p);
        let rg = *g.rotation.to_rotation_matrix().matrix();
        let w = g * nalgebra::Point3::from(self.wrist);
        let w = w.coords;
        let a1 = pick_cs(
            sp4_cs(&(w - p[0]), &h[0], &h[1], h[1].dot(&(self.wrist - p[0])), tol),
            seed[0],
        );
        if !a1.angles.exact && !keep {
            return;
        }
        let refs = self.flag_refs();
        for (q1, cs1) in a1.iter() {
            let r1 = rot_cs(&h[0], cs1);
            let y = self.inv_apply(0, &r1, &w);
            let shoulder_back = (y - p[0]).dot(&self.forward) < 0.0;
            let a3 = pick_cs(
                sp3_cs(
                    &h[2],
                    &(self.wrist - p[2]),
                    &(p[1] - p[2]),
                    (y - p[1]).norm(),
                    tol,
                ),
                seed[2],
            );
            if !a3.angles.exact && !keep {
                continue;
            }
            for (q3, cs3) in a3.iter() {
                let r3 = rot_cs(&h[2], cs3);
                let e3w = r3 * (self.wrist - p[2]) + p[2];
                let a2 = pick_cs(sp1_cs(&h[1], &(e3w - p[1]), &(y - p[1]), tol), seed[1]);
                let q2 = a2.angles.angles[0];
                let r123 = r1 * rot_cs(&h[1], a2.cs[0]) * r3;
                let r36 = r123.tr_mul(&rg);
                let exact = a1.angles.exact && a3.angles.exact && a2.angles.exact;
                let singular = a1.angles.free || a3.angles.free || a2.angles.free;
                let arm = ([q1, q2, q3], shoulder_back, refs.elbow_down(cs3));
                self.wrist_into(&r36, seed, (keep, tol), (arm, exact, singular), &refs, out);
            }
        }
    }

    /// The cosines and sines of the flags' reference angles.
    fn flag_refs(&self) -> FlagRefs {
        let (s3, c3) = self.q3_stretched.sin_cos();
        let (s5, c5) = self.q5_singular.sin_cos();
        FlagRefs {
            q3: (c3, s3),
            q5: (c5, s5),
        }
    }

    /// The spherical wrist for `R₃₆ = R₄R₅R₆`: `q₅` by subproblem 4 from
    /// `h₄ᵀ R₅ h₆ = h₄ᵀ R₃₆ h₆`, `q₄` and `q₆` by subproblem 1; pushes each
    /// solution with the arm's joints, flags and state.
    #[allow(clippy::type_complexity)]
    fn wrist_into(
        &self,
        r36: &Matrix3<f64>,
        seed: &[f64; 6],
        (keep, tol): (bool, f64),
        ((arm, shoulder_back, elbow_down), exact, singular): (([f64; 3], bool, bool), bool, bool),
        refs: &FlagRefs,
        out: &mut Base,
    ) {
        let h = &self.h;
        let r36h6 = r36 * h[5];
        let a5 = pick_cs(sp4_cs(&h[3], &h[4], &h[5], h[3].dot(&r36h6), tol), seed[4]);
        if !a5.angles.exact && !keep {
            return;
        }
        for (q5, cs5) in a5.iter() {
            let r5 = rot_cs(&h[4], cs5);
            let a4 = pick_cs(sp1_cs(&h[3], &(r5 * h[5]), &r36h6, tol), seed[3]);
            let r45 = rot_cs(&h[3], a4.cs[0]) * r5;
            let a6 = pick(sp1(&h[5], &self.x6, &(r45.tr_mul(r36) * self.x6), tol), seed[5]);
            let exact = exact && a5.angles.exact && a4.angles.exact && a6.exact;
            if !exact && !keep {
                continue;
            }
            let singular = singular || a5.angles.free || a4.angles.free || a6.free;
            let q = [arm[0], arm[1], arm[2], a4.angles.angles[0], q5, a6.angles[0]];
            let config = ConfigFlags {
                shoulder_back,
                elbow_down,
                wrist_flipped: refs.wrist_flipped(cs5),
            };
            out.push(q, config, singular, exact);
        }
    }

    /// Spherical wrist and spherical shoulder `s` (axes 1, 2 meet): `q₃` by
    /// subproblem 3 from `‖E₃ w₀ − s‖ = ‖w − s‖`, `(q₁, q₂)` by subproblem 2 from
    /// `R₁R₂ (E₃ w₀ − s) = w − s`, then the wrist as for [`Family::SphericalWrist`].
    /// A branch whose `q₁, q₂, q₃` lie `bound` (rad²) or farther from the
    /// seed's (nearest whole turns) is dropped before its wrist is solved.
    fn spherical_shoulder(
        &self,
        g: &Isometry3<f64>,
        seed: &[f64; 6],
        (keep, tol, bound): (bool, f64, f64),
        out: &mut Base,
    ) {
        let (h, p, s) = (&self.h, &self.p, self.shoulder);
        let rg = *g.rotation.to_rotation_matrix().matrix();
        let w = (g * nalgebra::Point3::from(self.wrist)).coords;
        let a3 = pick_cs(
            sp3_cs(&h[2], &(self.wrist - p[2]), &(s - p[2]), (w - s).norm(), tol),
            seed[2],
        );
        if !a3.angles.exact && !keep {
            return;
        }
        let refs = self.flag_refs();
        for (q3, cs3) in a3.iter() {
            let r3 = rot_cs(&h[2], cs3);
            let v = r3 * (self.wrist - p[2]) + p[2] - s;
            let pairs = sp2(&h[0], &h[1], &v, &(w - s), tol);
            if !pairs.exact && !keep {
                continue;
            }
            for &(q1, q2) in &pairs.pairs[..pairs.count] {
                // shoulder singularity (w on axis 1): q₁ from the seed, q₂ follows
                let (q1, q2) = if pairs.free.0 {
                    let q1 = wrap(seed[0]);
                    let a2 = pick(sp1(&h[1], &v, &rot(&h[0], q1).tr_mul(&(w - s)), tol), seed[1]);
                    (q1, a2.angles[0])
                } else {
                    (q1, q2)
                };
                let arm_d =
                    wrap(q1 - seed[0]).powi(2) + wrap(q2 - seed[1]).powi(2) + wrap(q3 - seed[2]).powi(2);
                if arm_d >= bound {
                    continue;
                }
                let r1 = rot(&h[0], q1);
                let y = self.inv_apply(0, &r1, &w);
                let r36 = (r1 * rot(&h[1], q2) * r3).tr_mul(&rg);
                let arm = (
                    [q1, q2, q3],
                    (y - p[0]).dot(&self.forward) < 0.0,
                    refs.elbow_down(cs3),
                );
                let exact = a3.angles.exact && pairs.exact;
                let singular = a3.angles.free || pairs.free.0 || pairs.free.1;
                self.wrist_into(&r36, seed, (keep, tol), (arm, exact, singular), &refs, out);
            }
        }
    }

    /// Three parallel: see [`AnalyticArm::solve_into`]. The subproblems give
    /// each angle's cosine and sine with it ([`sp4_cs`], [`sp1_cs`]), so the
    /// rotations are built without trigonometric calls; `R₂₃₄ x₂` is applied
    /// as four matrix–vector products; `E₃ (p₄ − p₃)` by Rodrigues on the
    /// vector; the flags are signs of `sin(q − q_ref) = sin q cos q_ref −
    /// cos q sin q_ref`.
    fn three_parallel(&self, g: &Isometry3<f64>, seed: &[f64; 6], keep: bool, tol: f64, out: &mut Base) {
        let (h, p) = (&self.h, &self.p);
        let rg = *g.rotation.to_rotation_matrix().matrix();
        let w = (g * nalgebra::Point3::from(self.wrist)).coords;
        let a1 = pick_cs(
            sp4_cs(&(w - p[0]), &h[0], &h[1], h[1].dot(&(self.wrist - p[0])), tol),
            seed[0],
        );
        if !a1.angles.exact && !keep {
            return;
        }
        let refs = self.flag_refs();
        // E₃ (p₄ − p₃) − p₂ = p₃ − p₂ + u∥ + cos q₃ u⊥ + sin q₃ (h₃ × u), u = p₄ − p₃
        let u = p[3] - p[2];
        let u_par = h[2] * h[2].dot(&u);
        let (u_perp, u_cross) = (u - u_par, h[2].cross(&u));
        let e3_fixed = p[2] - p[1] + u_par;
        let rg6 = rg * h[5];
        for (q1, cs1) in a1.iter() {
            let r1 = rot_cs(&h[0], cs1);
            let r1h2 = r1 * h[1];
            let a5 = pick_cs(sp4_cs(&h[1], &h[4], &h[5], r1h2.dot(&rg6), tol), seed[4]);
            if !a5.angles.exact && !keep {
                continue;
            }
            let yw = self.inv_apply(0, &r1, &w) - p[0];
            let shoulder_back = yw.dot(&self.forward) < 0.0;
            let rg_r1h2 = rg.tr_mul(&r1h2);
            for (q5, cs5) in a5.iter() {
                let r5 = rot_cs(&h[4], cs5);
                let a6 = pick_cs(sp1_cs(&h[5], &rg_r1h2, &r5.tr_mul(&h[1]), tol), seed[5]);
                let (q6, cs6) = (a6.angles.angles[0], a6.cs[0]);
                let r6 = rot_cs(&h[5], cs6);
                // R₂₃₄ x₂ = R₁ᵀ R_G R₆ᵀ R₅ᵀ x₂
                let r234x2 = r1.tr_mul(&(rg * r6.tr_mul(&r5.tr_mul(&self.x2))));
                let theta = sp1(&h[1], &self.x2, &r234x2, tol);
                // y = E₁⁻¹ G E₆⁻¹ E₅⁻¹ p₄
                let a = self.inv_apply(4, &r5, &p[3]);
                let b = self.inv_apply(5, &r6, &a);
                let c = g * nalgebra::Point3::from(b);
                let y = self.inv_apply(0, &r1, &c.coords);
                let a3 = pick_cs(
                    sp3_cs(&h[2], &(p[3] - p[2]), &(p[1] - p[2]), (y - p[1]).norm(), tol),
                    seed[2],
                );
                if !a3.angles.exact && !keep {
                    continue;
                }
                let wrist_flipped = refs.wrist_flipped(cs5);
                for (q3, (c3, s3)) in a3.iter() {
                    let e3 = e3_fixed + u_perp * c3 + u_cross * s3;
                    let a2 = pick(sp1(&h[1], &e3, &(y - p[1]), tol), seed[1]);
                    let q2 = a2.angles[0];
                    let q4 = wrap(self.s4 * (theta.angles[0] - q2 - self.s3 * q3));
                    let exact = a1.angles.exact
                        && a5.angles.exact
                        && a6.angles.exact
                        && theta.exact
                        && a3.angles.exact
                        && a2.exact;
                    if !exact && !keep {
                        continue;
                    }
                    let singular =
                        a1.angles.free || a5.angles.free || a6.angles.free || a3.angles.free || a2.free;
                    let config = ConfigFlags {
                        shoulder_back,
                        elbow_down: refs.elbow_down((c3, s3)),
                        wrist_flipped,
                    };
                    out.push([q1, q2, q3, q4, q5, q6], config, singular, exact);
                }
            }
        }
    }
}
