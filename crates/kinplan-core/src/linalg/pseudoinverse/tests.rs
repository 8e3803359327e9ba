use super::fixed::{MAX_FIXED, ROUND_ROBIN};
use super::*;

fn lcg_matrix(m: usize, n: usize, seed: u64) -> DMatrix<f64> {
    let mut s = seed;
    DMatrix::from_fn(m, n, |_, _| {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    })
}

/// Sweep counts pinned on fixed matrices, for the fixed-size path (≤ 8 rows)
/// and the general one: a wrong cached column norm still converges, only
/// slower, so correctness tests alone would not notice it (checked: leaving
/// `norms[i]` stale after a rotation fails only this test).
const PINNED_SWEEPS: [usize; 7] = [5, 5, 4, 6, 2, 2, 8];

#[test]
fn sweep_counts_are_pinned() {
    let mut got = Vec::new();
    for (m, n) in [(6, 6), (6, 7), (3, 6), (13, 7), (2, 9), (9, 2), (12, 12)] {
        let a = lcg_matrix(m, n, (m * 17 + n) as u64);
        let mut ws = SvdWorkspace::new(m, n);
        got.push(ws.decompose(&a));
    }
    eprintln!("sweeps: {got:?}");
    assert_eq!(got, PINNED_SWEEPS);
}

/// Reference sweep count of the fixed-size path, derived without its norm cache:
/// the same cyclic one-sided Jacobi method (cold start, `W = Â`, round-robin pair
/// order, stop after a sweep without rotation) with every `‖wᵢ‖²`, `‖wⱼ‖²`, `wᵢᵀwⱼ`
/// recomputed from the columns before each pair and the rotation in the textbook
/// `ζ` form ([`jacobi_rotation`](super::svd::jacobi_rotation)).
fn reference_fixed_sweeps(a: &DMatrix<f64>) -> usize {
    let (m, n) = a.shape();
    let at = if m < n { a.transpose() } else { a.clone() };
    let k = at.ncols();
    let mut w: Vec<Vec<f64>> = (0..k).map(|j| at.column(j).iter().copied().collect()).collect();
    let negligible = f64::EPSILON * f64::EPSILON * a.norm_squared();
    let tol2 = SvdWorkspace::DEFAULT_ORTHOGONALITY * SvdWorkspace::DEFAULT_ORTHOGONALITY;
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(p, q)| p * q).sum::<f64>();
    for sweep in 1..=super::svd::MAX_SWEEPS {
        let mut rotated = false;
        for &(i, j) in &ROUND_ROBIN[k][..k * k.saturating_sub(1) / 2] {
            let (i, j) = (i as usize, j as usize);
            let (alpha, beta, gamma) = (dot(&w[i], &w[i]), dot(&w[j], &w[j]), dot(&w[i], &w[j]));
            if alpha <= negligible || beta <= negligible || gamma * gamma <= tol2 * alpha * beta {
                continue;
            }
            let Some((c, s)) = super::svd::jacobi_rotation(alpha, beta, gamma, negligible, 0.0) else {
                continue;
            };
            rotated = true;
            for r in 0..w[i].len() {
                let (x, y) = (w[i][r], w[j][r]);
                w[i][r] = c * x - s * y;
                w[j][r] = s * x + c * y;
            }
        }
        if !rotated {
            return sweep;
        }
    }
    super::svd::MAX_SWEEPS
}

/// The fixed-size kernel caches squared column norms across a sweep; a wrong
/// update (stale, or with the sign of `tγ` flipped) still converges, only in more
/// sweeps, so the answers alone would not show it. Its sweep counts must equal
/// those of the cache-free reference on every small shape.
#[test]
fn fixed_path_sweeps_match_a_cache_free_reference() {
    let mut compared = 0;
    for m in 1..=MAX_FIXED {
        for n in 1..=MAX_FIXED {
            for seed in 0..4u64 {
                let a = lcg_matrix(m, n, seed * 1000 + (m * 10 + n) as u64);
                let mut ws = SvdWorkspace::new(m, n);
                let got = ws.decompose(&a);
                let want = reference_fixed_sweeps(&a);
                assert_eq!(got, want, "{m}x{n} seed {seed}");
                compared += usize::from(m.min(n) >= 3);
            }
        }
    }
    assert!(compared > 100);
}

#[test]
fn jacobi_matches_nalgebra_singular_values() {
    for (m, n) in [(6, 6), (6, 7), (3, 6), (13, 7), (2, 9), (9, 2)] {
        let a = lcg_matrix(m, n, (m * 31 + n) as u64);
        let mut ws = SvdWorkspace::new(m, n);
        ws.decompose(&a);
        let mut ours: Vec<f64> = ws.singular_values().iter().cloned().collect();
        ours.sort_by(|x, y| y.total_cmp(x));
        let theirs = a.clone().svd(false, false).singular_values;
        for (k, s) in theirs.iter().enumerate() {
            assert!((ours[k] - s).abs() < 1e-10, "{m}x{n} σ{k}: {} vs {}", ours[k], s);
        }
        for s in ours.iter().skip(theirs.len()) {
            assert!(s.abs() < 1e-10);
        }
    }
}

#[test]
fn workspace_matches_nalgebra_pseudoinverse_on_rank_deficient() {
    let mut a = lcg_matrix(6, 7, 5);
    // make column 3 a copy of column 1 and column 5 zero
    let c1 = a.column(1).into_owned();
    a.set_column(3, &c1);
    a.column_mut(5).fill(0.0);
    let b = DVector::from_fn(6, |i, _| i as f64 - 2.5);
    let reference = a.clone().pseudo_inverse(1e-10).unwrap() * &b;
    let mut ws = SvdWorkspace::new(1, 1);
    let mut x = DVector::zeros(0);
    ws.solve_into(&a, &b, 0.0, &PseudoinverseParams::default(), &mut x)
        .unwrap();
    assert!((x - reference).norm() < 1e-9);
}

#[test]
fn damped_solution_matches_normal_equations() {
    let a = lcg_matrix(6, 6, 11);
    let b = DVector::from_fn(6, |i, _| (i as f64).sin());
    let mu = 0.3;
    let lhs = a.transpose() * &a + DMatrix::identity(6, 6) * mu;
    let reference = lhs.lu().solve(&(a.transpose() * &b)).unwrap();
    let mut ws = SvdWorkspace::new(6, 6);
    let mut x = DVector::zeros(6);
    ws.solve_into(&a, &b, mu, &PseudoinverseParams::default(), &mut x)
        .unwrap();
    assert!((x - reference).norm() < 1e-10);
}

/// Checks one decomposition held in `ws` against `a`: `Â V = W` (so `A = U Σ Vᵀ` with
/// `U = W Σ⁻¹`), `V` orthogonal, `W` columns orthogonal, singular values = nalgebra's.
fn check_decomposition(ws: &SvdWorkspace, a: &DMatrix<f64>, what: &str) {
    let (m, n) = a.shape();
    let ahat = if m < n { a.transpose() } else { a.clone() };
    let k = ahat.ncols();
    let scale = a.norm().max(1.0);
    // exact reconstruction Â = W Vᵀ
    let recon = &ws.w * ws.v.transpose();
    assert!(
        (&recon - &ahat).norm() <= 1e-13 * scale,
        "{what}: reconstruction {}",
        (&recon - &ahat).norm()
    );
    // V orthogonal
    let vtv = ws.v.transpose() * &ws.v;
    assert!(
        (vtv - DMatrix::identity(k, k)).norm() <= 1e-13,
        "{what}: V not orthogonal"
    );
    // W columns orthogonal (relative to their norms), i.e. U orthogonal on σ > 0
    for i in 0..k {
        for j in (i + 1)..k {
            let (wi, wj) = (ws.w.column(i), ws.w.column(j));
            let (ni, nj) = (wi.norm(), wj.norm());
            if ni > 1e-12 * scale && nj > 1e-12 * scale {
                assert!(wi.dot(&wj).abs() <= 1e-9 * ni * nj, "{what}: w{i}·w{j}");
            }
        }
    }
    let mut ours: Vec<f64> = ws.singular_values().iter().cloned().collect();
    ours.sort_by(|x, y| y.total_cmp(x));
    let theirs = a.clone().svd(false, false).singular_values;
    for (i, s) in theirs.iter().enumerate() {
        assert!(
            (ours[i] - s).abs() <= 1e-12 * scale,
            "{what}: σ{i} {} vs {}",
            ours[i],
            s
        );
    }
    for s in ours.iter().skip(theirs.len()) {
        assert!(s.abs() <= 1e-12 * scale, "{what}: extra σ {s}");
    }
}

#[test]
fn fixed_size_path_decomposes_every_small_shape() {
    // every shape with max(m, n) ≤ 8 (fixed-size path), plus shapes on the general path
    let mut shapes: Vec<(usize, usize)> = (1..=8).flat_map(|m| (1..=8).map(move |n| (m, n))).collect();
    shapes.extend([(9, 6), (6, 9), (12, 10), (3, 11)]);
    for (m, n) in shapes {
        for seed in 0..4u64 {
            let mut a = lcg_matrix(m, n, 1000 + seed * 97 + (m * 13 + n) as u64);
            if seed == 2 && n >= 3 {
                // rank-deficient: a repeated column and a zero column
                let c0 = a.column(0).into_owned();
                a.set_column(n - 1, &c0);
                a.column_mut(1).fill(0.0);
            }
            if seed == 3 && m >= 2 {
                // rank-deficient: a row that is a combination of two others
                let r = a.row(0) * 0.5 - a.row(1) * 2.0;
                a.set_row(m - 1, &r);
            }
            let mut ws = SvdWorkspace::new(m, n);
            ws.decompose(&a);
            check_decomposition(&ws, &a, &format!("{m}x{n} seed {seed} cold"));
            // warm start from the previous rotation on a nearby matrix
            let b = &a + lcg_matrix(m, n, 7 + seed) * 0.05;
            ws.decompose_warm(&b);
            check_decomposition(&ws, &b, &format!("{m}x{n} seed {seed} warm"));
        }
    }
}

#[test]
fn fixed_size_path_matches_general_path() {
    // The fixed-size code (cached norms, two-root rotation) and the general slice code
    // must give the same decomposition up to rounding.
    for (m, n) in [(6, 6), (6, 7), (3, 6), (7, 6), (5, 8)] {
        let a = lcg_matrix(m, n, (m * 7 + n) as u64);
        let mut fast = SvdWorkspace::new(m, n);
        fast.decompose(&a);
        let mut slow = SvdWorkspace::new(m, n);
        let ahat = if m < n { a.transpose() } else { a.clone() };
        slow.w.copy_from(&ahat);
        slow.v.fill_with_identity();
        slow.sweep_until_orthogonal(a.norm_squared());
        let b = DVector::from_fn(m, |i, _| (i as f64 * 0.7).cos());
        let (mut xf, mut xs) = (DVector::zeros(n), DVector::zeros(n));
        for mu in [0.0, 1e-3, 0.5] {
            fast.solve_decomposed(&b, mu, 1e-10, &mut xf);
            slow.solve_decomposed(&b, mu, 1e-10, &mut xs);
            assert!((&xf - &xs).norm() <= 1e-10 * xs.norm().max(1.0), "{m}x{n} μ={mu}");
        }
    }
}

/// Every round-robin table visits each column pair exactly once, in rounds of
/// disjoint pairs.
#[test]
fn round_robin_tables_cover_every_pair_once() {
    for k in 2..=MAX_FIXED {
        let pairs = &ROUND_ROBIN[k][..k * (k - 1) / 2];
        let mut seen = std::collections::HashSet::new();
        for &(i, j) in pairs {
            assert!(i < j && (j as usize) < k, "k={k}: ({i}, {j})");
            assert!(seen.insert((i, j)), "k={k}: ({i}, {j}) twice");
        }
        let per_round = k / 2;
        for round in pairs.chunks(per_round) {
            let mut cols: Vec<u8> = round.iter().flat_map(|&(i, j)| [i, j]).collect();
            cols.sort_unstable();
            cols.dedup();
            assert_eq!(
                cols.len(),
                2 * round.len(),
                "k={k}: round {round:?} shares a column"
            );
        }
    }
}

/// The AVX2 build of the fixed-size sweeps must give bit-identical factors (no FMA:
/// every operation rounds as in the portable build).
#[cfg(target_arch = "x86_64")]
#[test]
fn avx2_path_is_bit_identical_to_portable() {
    if !std::arch::is_x86_feature_detected!("avx2") {
        return;
    }
    for (m, n) in [(6, 6), (6, 7), (3, 6), (3, 7), (6, 3), (2, 5), (8, 8), (7, 4)] {
        for seed in 0..10u64 {
            let a = lcg_matrix(m, n, seed * 131 + (7 * m + n) as u64);
            let mut portable = SvdWorkspace::new(m, n);
            let mut avx2 = SvdWorkspace::new(m, n);
            let s1 = portable.decompose_from_v_portable(&a);
            // SAFETY: AVX2 support checked above.
            let s2 = unsafe { avx2.decompose_from_v_avx2(&a) };
            assert_eq!(s1, s2, "{m}x{n}: sweeps");
            assert_eq!(portable.w.as_slice(), avx2.w.as_slice(), "{m}x{n}: W");
            assert_eq!(portable.v.as_slice(), avx2.v.as_slice(), "{m}x{n}: V");
            assert_eq!(portable.sigma.as_slice(), avx2.sigma.as_slice(), "{m}x{n}: σ");
        }
    }
}

/// A looser orthogonality tolerance τ still gives an exact factorisation `A V = W`
/// with orthogonal `V`; the singular values are accurate to ~τ² and a damped solution
/// to ~τ times the conditioning (here ≤ 1e-3 relative for τ = 1e-4).
#[test]
fn orthogonality_tolerance_bounds_the_error() {
    for (m, n) in [(6, 6), (6, 7), (3, 7)] {
        for seed in 0..20u64 {
            let a = lcg_matrix(m, n, seed * 17 + (5 * m + n) as u64);
            let b = DVector::from_fn(m, |i, _| (i as f64 * 0.7 + seed as f64).cos());
            let mut exact = SvdWorkspace::new(m, n);
            let mut loose = SvdWorkspace::new(m, n).with_orthogonality(1e-4);
            let s_exact = exact.decompose(&a);
            let s_loose = loose.decompose(&a);
            assert!(s_loose <= s_exact, "{m}x{n}: {s_loose} > {s_exact} sweeps");
            check_decomposition_identity(&loose, &a);
            let mut e: Vec<f64> = exact.singular_values().iter().copied().collect();
            let mut l: Vec<f64> = loose.singular_values().iter().copied().collect();
            e.sort_by(f64::total_cmp);
            l.sort_by(f64::total_cmp);
            let smax = e[e.len() - 1];
            for (x, y) in e.iter().zip(&l) {
                assert!((x - y).abs() <= 1e-7 * smax, "{m}x{n}: σ {e:?} vs {l:?}");
            }
            let (mut xe, mut xl) = (DVector::zeros(n), DVector::zeros(n));
            exact.solve_decomposed(&b, 1e-3, 1e-12, &mut xe);
            loose.solve_decomposed(&b, 1e-3, 1e-12, &mut xl);
            assert!((&xe - &xl).norm() <= 1e-3 * xe.norm(), "{m}x{n}: {xe} vs {xl}");
        }
    }
}

/// `Â V = W` and `VᵀV = I` (holds at any orthogonality tolerance: rotations are exact
/// up to rounding).
fn check_decomposition_identity(ws: &SvdWorkspace, a: &DMatrix<f64>) {
    let a_hat = if ws.transposed { a.transpose() } else { a.clone() };
    let k = ws.v.ncols();
    assert!((&a_hat * &ws.v - &ws.w).norm() <= 1e-12 * a.norm());
    assert!((ws.v.transpose() * &ws.v - DMatrix::identity(k, k)).norm() <= 1e-12);
}

#[test]
fn damped_solution_matches_normal_equations_on_jacobian_shapes() {
    for (m, n) in [(6, 6), (6, 7), (3, 6), (3, 7), (6, 3)] {
        let a = lcg_matrix(m, n, (31 * m + n) as u64);
        let b = DVector::from_fn(m, |i, _| (i as f64).sin() + 0.3);
        let mut ws = SvdWorkspace::new(m, n);
        let mut x = DVector::zeros(n);
        for mu in [1e-7, 1e-3, 0.3, 10.0] {
            let lhs = a.transpose() * &a + DMatrix::identity(n, n) * mu;
            let reference = lhs.lu().solve(&(a.transpose() * &b)).unwrap();
            ws.solve_into(&a, &b, mu, &PseudoinverseParams::default(), &mut x)
                .unwrap();
            assert!(
                (&x - &reference).norm() <= 1e-8 * reference.norm().max(1.0),
                "{m}x{n} μ={mu}"
            );
        }
    }
}

#[test]
fn bad_inputs_are_errors() {
    let a = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, f64::NAN]);
    let b = DVector::from_vec(vec![1.0, 2.0]);
    let p = PseudoinverseParams::default();
    assert!(matches!(
        solve_pseudoinverse(&a, &b, &p),
        Err(LinalgError::NonFinite {
            what: crate::linalg::Operand::A
        })
    ));
    let a = DMatrix::identity(2, 2);
    let b3 = DVector::from_vec(vec![1.0, 2.0, 3.0]);
    assert!(matches!(
        solve_pseudoinverse(&a, &b3, &p),
        Err(LinalgError::ShapeMismatch { .. })
    ));
    let e = DMatrix::<f64>::zeros(0, 2);
    assert!(matches!(
        solve_pseudoinverse(&e, &DVector::zeros(0), &p),
        Err(LinalgError::Empty { .. })
    ));
    let bad = PseudoinverseParams {
        relative_tolerance: -1.0,
    };
    assert!(solve_pseudoinverse(&a, &b, &bad).is_err());
}
