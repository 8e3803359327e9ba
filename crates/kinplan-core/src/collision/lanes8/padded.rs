//! Eight pieces of motion proved free at once: the padded check of
//! [`super::super::padded_motion`] in the lanes of [`Lanes8`].
//!
//! A piece is `q(σ) = m + σ·d`, `|σ| ≤ 1`, with its midpoint `m` in a lane
//! and the half vector `d` shared by the batch (the pieces of one motion
//! at one level of halving have the same). Every sphere of the sphere model
//! is grown by how far the body points inside it can move along the piece,
//! the second-order bound of the `sweep` module applied to the sphere
//! instead of the body's bounding sphere: for a sphere of body `b` centred
//! at `x` (at `m`) with radius `r`,
//!
//! ```text
//! pad = |Ω_k × x − M_k| + |Ω_k|·r + A_b/2,
//! Ω_k = Σ_{j≤k} d_j ω_j,   M_k = Σ_{j≤k} d_j ω_j × o_j,
//! A_b = Σ_{j≤k} L_{j,b} |d_j| (3 P_j + |d_j|),   P_j = Σ_{i<j} |d_i|,
//! ```
//!
//! with `k` the last joint moving `b`, `ω_j`, `o_j` joint `j`'s axis and a
//! point on it at `m`, `L_{j,b}` the lever of [`SweepBound`]. A body point
//! `y` in the sphere moves by at most `|Ω_k × y − M_k| + A_b/2` (`sweep`
//! module doc), and `|Ω_k × y − M_k| ≤ |Ω_k × x − M_k| + |Ω_k|·|y − x|`.
//! So the body swept over the piece stays inside its spheres grown by their
//! pads, and grown spheres clear of the scene and of the checked bodies'
//! grown spheres prove the piece free (Schwarzer, Saha and Latombe's
//! conservative advancement with the distance test replaced by the
//! spheres).
//!
//! Rounding: the axes and points come from the `f32` kinematics, whose
//! rotation rows are within `ρ` and points within the body's margin `E`
//! (`lanes8_bound`), and the sums are evaluated in `f32`. Per joint this
//! misplaces `d_j ω_j × (x − o_j)` by at most
//! `|d_j|·(√3ρ·(L + e) + 2E(1 + √3ρ))` (`e` bounds how far a sphere reaches
//! past the body's bounding sphere), `|Ω_k|·r` by `|d_j|·√3ρ·e`, and the
//! `f32` sums by `|d_j|·38u·(2X + L + e)` (`X` bounds every coordinate);
//! [`Lanes8::pad_terms`] adds `Σ_j |d_j|·κ_{j,b}` with
//! `κ = 2√3ρ(L + e) + 2E(1 + √3ρ) + 64u(2X + L + e)` to `A_b/2` in `f64` and
//! rounds up, and the pad's own `f32` evaluation (a square root, two sums
//! and a product: relative `< 8u`) is covered by scaling it by
//! `1 + 2⁻¹⁶`. The threshold `(R)²·GROW` covers the rounding of
//! `R = r + pad` and its square, as in the state check.

use std::mem::MaybeUninit;

use super::super::lanes8_bound::{SLACK, U};
use super::super::scene_checker::SELF_PAIRS;
use super::super::sweep::SweepBound;
use super::super::trig32::MAX_TURN;
use super::{
    Ball, Frame8, Lane8, Lanes8, MAX_BODIES8, MAX_DOF8, MAX_FINE8, MAX_LEAVES8, WIDTH, assume_init, dist2,
    for_bits, mask_each, place, prim_dist2, uninit_frames, up,
};

/// `1 + 2⁻¹⁶`: the pad's `f32` evaluation, scaled up (module doc).
const PAD_SCALE: f32 = 1.0 + 1.0 / 65_536.0;
/// `d² > R²·GROW` clears (as `super::GROW`).
const GROW: f32 = super::GROW;

/// The prefix sums of one piece at one joint, per lane: `Ω_j` and `M_j`
/// (module doc).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sums8 {
    omega: [Lane8; 3],
    moment: [Lane8; 3],
}

impl Sums8 {
    pub(super) const ZERO: Sums8 = Sums8 {
        omega: [[0.0; WIDTH]; 3],
        moment: [[0.0; WIDTH]; 3],
    };

    /// Adds joint `j`'s terms: `d_j·ω` and `d_j·(ω × o)`.
    #[inline(always)]
    pub(super) fn add(&mut self, dj: f32, w: [Lane8; 3], o: &[Lane8; 3]) {
        for l in 0..WIDTH {
            let (wx, wy, wz) = (w[0][l] * dj, w[1][l] * dj, w[2][l] * dj);
            self.omega[0][l] += wx;
            self.omega[1][l] += wy;
            self.omega[2][l] += wz;
            self.moment[0][l] += wy * o[2][l] - wz * o[1][l];
            self.moment[1][l] += wz * o[0][l] - wx * o[2][l];
            self.moment[2][l] += wx * o[1][l] - wy * o[0][l];
        }
    }

    /// Sphere `s` placed at `x`, its radius grown per lane by its pad
    /// ([`Sums8::pad`]) and the pad's `constant` term.
    #[inline(always)]
    fn grown(&self, x: &[Lane8; 3], s: &Ball, constant: f32) -> Lane8 {
        let mut r = self.pad(x, s.r);
        for v in r.iter_mut() {
            *v += constant + s.r;
        }
        r
    }

    /// `self − other`, term by term.
    #[inline(always)]
    fn minus(&self, other: &Sums8) -> Sums8 {
        let mut out = *self;
        for k in 0..3 {
            for l in 0..WIDTH {
                out.omega[k][l] -= other.omega[k][l];
                out.moment[k][l] -= other.moment[k][l];
            }
        }
        out
    }

    /// The pad of a sphere centred at `x` with radius `r` (before the
    /// body's constant term), scaled up by [`PAD_SCALE`].
    #[inline(always)]
    fn pad(&self, x: &[Lane8; 3], r: f32) -> Lane8 {
        let (w, m) = (&self.omega, &self.moment);
        let mut out = [0.0f32; WIDTH];
        for l in 0..WIDTH {
            let vx = w[1][l] * x[2][l] - w[2][l] * x[1][l] - m[0][l];
            let vy = w[2][l] * x[0][l] - w[0][l] * x[2][l] - m[1][l];
            let vz = w[0][l] * x[1][l] - w[1][l] * x[0][l] - m[2][l];
            let turn = (w[0][l] * w[0][l] + w[1][l] * w[1][l] + w[2][l] * w[2][l]).sqrt();
            out[l] = ((vx * vx + vy * vy + vz * vz).sqrt() + turn * r) * PAD_SCALE;
        }
        out
    }
}

/// The pad's parts that are the same in every lane (module doc), rounded
/// up: per body (`None` for a body fixed to the base), and per checked self
/// pair the motion of one body relative to the other.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PadTerms<'a> {
    /// The bodies checked against the scene and the checked self pairs.
    scene_bodies: &'a [u16],
    self_pairs: &'a [(u16, u16)],
    /// The half vector, in `f32`.
    d: [f32; MAX_DOF8],
    body: [Option<f32>; MAX_BODIES8],
    pair: [PairPad; MAX_PAIRS],
}

impl PadTerms<'_> {
    /// Per body its constant term; per checked self pair `(distal, from,
    /// to, constant)`, `None` when the two do not move apart (tests).
    #[cfg(test)]
    #[allow(clippy::type_complexity)]
    pub(crate) fn constants(
        &self,
        pairs: usize,
    ) -> (Vec<Option<f32>>, Vec<Option<(usize, Option<usize>, usize, f32)>>) {
        let pair = self.pair[..pairs]
            .iter()
            .map(|p| match *p {
                PairPad::Rigid => None,
                PairPad::Relative {
                    distal,
                    from,
                    to,
                    constant,
                    ..
                } => Some((distal as usize, from.map(usize::from), to as usize, constant)),
            })
            .collect();
        (self.body.to_vec(), pair)
    }
}

/// The bodies of a self pair that joints move apart, and the last joint
/// moving each ([`Lanes8::pad_terms`]).
#[derive(Debug, Clone, Copy)]
struct PairChain {
    proximal: usize,
    distal: usize,
    from: Option<usize>,
    to: usize,
}

/// Checked self pairs the padded batch takes (more: none proved).
const MAX_PAIRS: usize = 64;

/// How one checked self pair is padded: the joints from the common part of
/// the chain up to the proximal body (`0..=from`) move both bodies
/// together, so only the joints `from + 1..=to` move the distal body
/// relative to the proximal one, and only the distal body's spheres are
/// grown, by that relative motion (the bound of the module doc in the
/// proximal body's frame: `Ω_to − Ω_from`, `M_to − M_from`, and `P_j`
/// summed from `from + 1`).
#[derive(Debug, Clone, Copy)]
enum PairPad {
    /// Neither body moves relative to the other.
    Rigid,
    Relative {
        proximal: u8,
        distal: u8,
        from: Option<u8>,
        to: u8,
        constant: f32,
    },
}

impl Lanes8 {
    /// The constant pad terms of the pieces with half vector `d`, checked
    /// against the scene around `scene_bodies` and for the `self_pairs`;
    /// `None` when the batch cannot prove pieces of this
    /// model (a sliding joint, more than 64 self pairs, or `sweep` not of
    /// this model) or of this length (a joint's half step beyond
    /// `trig32::MAX_TURN`, or not a number: the `f32` sums stay finite
    /// below it).
    pub(crate) fn pad_terms<'a>(
        &self,
        sweep: &SweepBound,
        d: &[f64],
        scene_bodies: &'a [u16],
        self_pairs: &'a [(u16, u16)],
    ) -> Option<PadTerms<'a>> {
        if self.slides
            || d.len() != self.dof
            || !d.iter().all(|v| v.abs() <= MAX_TURN)
            || self_pairs.len() > MAX_PAIRS
        {
            return None;
        }
        let mut terms = PadTerms {
            scene_bodies,
            self_pairs,
            d: [0.0; MAX_DOF8],
            body: [None; MAX_BODIES8],
            pair: [PairPad::Rigid; MAX_PAIRS],
        };
        for (v, x) in terms.d.iter_mut().zip(d) {
            *v = *x as f32;
        }
        // the checked self pairs by distal body (bit: slot in `self_pairs`)
        let mut distal_of = [0u64; MAX_BODIES8];
        for (slot, &pair) in self_pairs.iter().enumerate() {
            if let Some(chain) = self.pair_chain(pair) {
                distal_of[chain.distal] |= 1 << slot;
            }
        }
        // per body, prefix sums over the joints (module doc):
        // x_j = Σ_{i≤j} L_i h_i (3 P_i + h_i), y_j = Σ_{i≤j} L_i h_i,
        // r_j = Σ_{i≤j} h_i κ_i, and P_j = Σ_{i<j} h_i
        let mut sums = [[0.0f64; 3]; MAX_DOF8];
        let mut before = [0.0f64; MAX_DOF8 + 1];
        for (j, dj) in d.iter().enumerate() {
            before[j + 1] = before[j] + dj.abs();
        }
        let sqrt3 = 3f64.sqrt();
        for b in 0..self.body_count {
            if sweep.last(b) != self.last[b] {
                return None;
            }
            let Some(k) = self.last[b] else {
                continue;
            };
            let e = self.reach_past[b];
            let (mut x, mut y, mut r) = (0.0, 0.0, 0.0);
            for (j, dj) in d.iter().enumerate().take(k + 1) {
                let (h, lever) = (dj.abs(), sweep.lever(b, j));
                x += lever * h * (3.0 * before[j] + h);
                y += lever * h;
                let kappa = 2.0 * sqrt3 * self.rho * (lever + e)
                    + 2.0 * self.margin[b] * (1.0 + sqrt3 * self.rho)
                    + 64.0 * U * (2.0 * self.reach + lever + e);
                r += h * kappa;
                sums[j] = [x, y, r];
            }
            terms.body[b] = Some(constant(x, r, 1.0)?);
            // the pairs whose distal body this is
            let mut bits = distal_of[b];
            while bits != 0 {
                let slot = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let Some(PairChain {
                    proximal, from, to, ..
                }) = self.pair_chain(self_pairs[slot])
                else {
                    continue; // not set in `distal_of`
                };
                // the joints from + 1..=to alone, P_j summed from from + 1:
                // Σ L h (3 (P − P_f) + h) = (x_to − x_f) − 3 P_f (y_to − y_f)
                let [x, y, r] = sums[to];
                let constant = match from {
                    None => constant(x, r, 1.0)?,
                    Some(f) => {
                        let [xf, yf, _] = sums[f];
                        let p = before[f + 1];
                        constant((x - xf) - 3.0 * p * (y - yf), r, 2.0)?
                    }
                };
                terms.pair[slot] = PairPad::Relative {
                    proximal: proximal as u8,
                    distal: b as u8,
                    from: from.map(|f| f as u8),
                    to: to as u8,
                    constant,
                };
            }
        }
        Some(terms)
    }

    /// How the self pair `(a, b)` moves: its distal body (the one more
    /// joints move), the last joint moving the proximal one (`None`: fixed
    /// to the base) and the distal one's; `None` when neither body moves
    /// relative to the other.
    fn pair_chain(&self, (a, b): (u16, u16)) -> Option<PairChain> {
        let (a, b) = (a as usize, b as usize);
        // `None` (fixed to the base) orders first
        let (proximal, distal) = if self.last[a] <= self.last[b] {
            (a, b)
        } else {
            (b, a)
        };
        let (from, to) = (self.last[proximal], self.last[distal]?);
        (from != Some(to)).then_some(PairChain {
            proximal,
            distal,
            from,
            to,
        })
    }

    /// Unsure lanes of the batch of piece midpoints `q` with the half
    /// vector, scene bodies and self pairs `terms` were made for
    /// ([`Lanes8::pad_terms`]; module doc): bit `l` clear when lane `l`'s
    /// grown spheres are clear of the scene around the scene bodies and of
    /// each other for the self pairs. `cleared[l]` gets what was proved
    /// clear in lane `l` even so: bit `b` the scene around body `b`, bit 63
    /// every self pair. The AVX2 build when the CPU has it, unless
    /// `portable`.
    pub(crate) fn unsure_padded(
        &self,
        q: &[Lane8],
        terms: &PadTerms,
        cleared: &mut [u64; WIDTH],
        portable: bool,
    ) -> u32 {
        #[cfg(target_arch = "x86_64")]
        if !portable && std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has the features the function is built for.
            return unsafe { self.unsure_padded_avx2(q, terms, cleared) };
        }
        let _ = portable;
        self.unsure_padded_in::<false>(q, terms, cleared)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn unsure_padded_avx2(&self, q: &[Lane8], terms: &PadTerms, cleared: &mut [u64; WIDTH]) -> u32 {
        self.unsure_padded_in::<true>(q, terms, cleared)
    }

    #[inline(always)]
    fn unsure_padded_in<const AVX: bool>(
        &self,
        q: &[Lane8],
        terms: &PadTerms,
        cleared: &mut [u64; WIDTH],
    ) -> u32 {
        const ALL: u32 = (1 << WIDTH) - 1;
        let (scene_bodies, self_pairs) = (terms.scene_bodies, terms.self_pairs);
        *cleared = [0; WIDTH];
        let mut frames = uninit_frames();
        let mut sums = [const { MaybeUninit::<Sums8>::uninit() }; MAX_DOF8];
        let frames = self.fk_with::<true>(q, &terms.d[..self.dof], &mut frames, &mut sums[..self.dof]);
        // SAFETY: the kinematics wrote the sums of every joint.
        let sums: &[Sums8] = unsafe { assume_init(&sums[..self.dof]) };
        // bounding spheres, placed and grown once
        let mut centres = [const { MaybeUninit::<([Lane8; 3], Lane8)>::uninit() }; MAX_BODIES8];
        for b in 0..self.body_count {
            let c = place(&frames[b], &self.coarse[b].c);
            let r = self.grown(sums, terms, b, &c, &self.coarse[b]);
            centres[b].write((c, r));
        }
        // SAFETY: the first `body_count` entries were just written.
        let centres: &[([Lane8; 3], Lane8)] = unsafe { assume_init(&centres[..self.body_count]) };
        let mut unsure = 0u32;
        let mut near = [const { MaybeUninit::<(u16, u32)>::uninit() }; MAX_LEAVES8];
        for &b in scene_bodies {
            let b = b as usize;
            let (c, r) = &centres[b];
            let t = threshold(r, &[0.0; WIDTH]);
            let mut count = 0;
            for (i, [lo, hi]) in self.boxes.iter().enumerate() {
                let mut d2 = [0.0f32; WIDTH];
                for k in 0..3 {
                    for l in 0..WIDTH {
                        let e = super::max(super::max(lo[k] - c[k][l], c[k][l] - hi[k]), 0.0);
                        d2[l] += e * e;
                    }
                }
                let m = mask_each::<AVX>(&d2, &t);
                if m != 0 {
                    near[count].write((i as u16, m));
                    count += 1;
                }
            }
            // SAFETY: the first `count` entries were just written.
            let near: &[(u16, u32)] = unsafe { assume_init(&near[..count]) };
            let mut hit = 0u32;
            if count != 0 {
                for s in &self.fine[self.start[b]..self.start[b + 1]] {
                    let x = place(&frames[b], &s.c);
                    let r = self.grown(sums, terms, b, &x, s);
                    for &(i, m) in near {
                        let (d2, radius) = prim_dist2(&x, &self.prims[i as usize]);
                        hit |= mask_each::<AVX>(&d2, &threshold(&r, &[radius; WIDTH])) & m;
                    }
                    if hit == ALL {
                        break;
                    }
                }
            }
            unsure |= hit;
            for_bits(!hit & ALL, |l| cleared[l] |= 1 << b);
        }
        let mut met = 0u32;
        for (i, &(a, b)) in self_pairs.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            met |= match terms.pair[i] {
                PairPad::Rigid => {
                    let reach = [self.coarse[a].r + self.coarse[b].r; WIDTH];
                    let m = mask_each::<AVX>(
                        &dist2(&centres[a].0, &centres[b].0),
                        &threshold(&reach, &[0.0; WIDTH]),
                    );
                    if m & !met == 0 {
                        continue;
                    }
                    // no relative motion: the state check's test at the midpoint
                    let (ca, cb) = (&centres[a].0, &centres[b].0);
                    self.fine_pairs_meet::<AVX>(&frames[a], a, &frames[b], b, ca, cb) & m
                }
                PairPad::Relative {
                    proximal,
                    distal,
                    from,
                    to,
                    constant,
                } => {
                    let (p, q) = (proximal as usize, distal as usize);
                    let from = from.map_or(Sums8::ZERO, |f| sums[f as usize]);
                    let rel = Relative {
                        sums: sums[to as usize].minus(&from),
                        constant,
                    };
                    let (cp, cq) = (&centres[p].0, &centres[q].0);
                    let reach = rel.grown(cq, &self.coarse[q]);
                    let m = mask_each::<AVX>(&dist2(cp, cq), &threshold(&[self.coarse[p].r; WIDTH], &reach));
                    if m & !met == 0 {
                        continue;
                    }
                    self.pair_meets::<AVX>(&rel, (&frames[p], p), (&frames[q], q)) & m
                }
            };
            if met == ALL {
                return ALL;
            }
        }
        for_bits(!met & ALL, |l| cleared[l] |= SELF_PAIRS);
        unsure | met
    }

    /// Sphere `s` of body `b`, placed at `x`: its radius grown by its pad
    /// per lane (module doc).
    #[inline(always)]
    fn grown(&self, sums: &[Sums8], terms: &PadTerms, b: usize, x: &[Lane8; 3], s: &Ball) -> Lane8 {
        match (self.last[b], terms.body[b]) {
            (Some(k), Some(constant)) => sums[k].grown(x, s, constant),
            _ => [s.r; WIDTH],
        }
    }

    /// Lanes where a fine sphere of the proximal body `p` meets one of the
    /// distal body `q`'s grown by their motion relative to `p` (`rel`);
    /// every pair of spheres tested (the padded batch meets few pairs).
    #[inline(always)]
    fn pair_meets<const AVX: bool>(
        &self,
        rel: &Relative,
        (fp, p): (&Frame8, usize),
        (fq, q): (&Frame8, usize),
    ) -> u32 {
        let mut placed = [const { MaybeUninit::<([Lane8; 3], Lane8)>::uninit() }; MAX_FINE8];
        let fine_q = &self.fine[self.start[q]..self.start[q + 1]];
        for (slot, t) in placed.iter_mut().zip(fine_q) {
            let y = place(fq, &t.c);
            slot.write((y, rel.grown(&y, t)));
        }
        // SAFETY: one entry per fine sphere of `q` (at most MAX_FINE8) was written.
        let placed: &[([Lane8; 3], Lane8)] = unsafe { assume_init(&placed[..fine_q.len()]) };
        let mut meet = 0u32;
        for s in &self.fine[self.start[p]..self.start[p + 1]] {
            let x = place(fp, &s.c);
            let r = [s.r; WIDTH];
            for (y, ry) in placed {
                meet |= mask_each::<AVX>(&dist2(&x, y), &threshold(&r, ry));
            }
        }
        meet
    }
}

/// The motion of a distal body relative to a proximal one over a piece:
/// the difference of their prefix sums and the constant term.
struct Relative {
    sums: Sums8,
    constant: f32,
}

impl Relative {
    /// Sphere `s` placed at `x`, its radius grown by its relative pad.
    #[inline(always)]
    fn grown(&self, x: &[Lane8; 3], s: &Ball) -> Lane8 {
        self.sums.grown(x, s, self.constant)
    }
}

/// A pad's constant term from its acceleration sum `accel` (the `A` of
/// the module doc) and rounding sum, the rounding counted `twice` for a
/// difference of prefix sums, rounded up (`f64` rounding in the slack).
fn constant(accel: f64, rounding: f64, twice: f64) -> Option<f32> {
    let constant = (0.5 * accel.max(0.0) + twice * rounding) * (1.0 + 1e-12) + SLACK;
    constant.is_finite().then(|| up(constant))
}

/// `(a + b)²·GROW` per lane.
#[inline(always)]
fn threshold(a: &Lane8, b: &Lane8) -> Lane8 {
    let mut t = [0.0f32; WIDTH];
    for l in 0..WIDTH {
        let reach = a[l] + b[l];
        t[l] = reach * reach * GROW;
    }
    t
}
