//! Octree tests: IO round trips, geb079.bt, hostile input, updates against hand-worked cases.

use super::*;

const GEB079: &str = "/usr/share/doc/liboctomap-dev/examples/data/geb079.bt";

fn geb079() -> Option<Vec<u8>> {
    match std::fs::read(GEB079) {
        Ok(b) => Some(b),
        Err(_) => {
            println!("SKIPPED: {GEB079} not present (apt-get install liboctomap-dev)");
            None
        }
    }
}

#[test]
fn geb079_reads_with_octomaps_counts_and_writes_back_identical() {
    let Some(bytes) = geb079() else { return };
    let t = Octree::read_bt(&bytes, &OctreeLimits::default()).unwrap();
    // figures OctoMap reports for this file (docs/octree.md#file-and-message-formats)
    assert_eq!(t.num_nodes(), 532_566);
    assert_eq!(t.leaf_counts(), (143_729, 284_415));
    assert_eq!(t.resolution(), 0.08);
    let out = t.write_bt();
    assert!(out == bytes, "written .bt differs from geb079.bt");
    // .ot round trip keeps every value
    let ot = t.write_ot();
    let t2 = Octree::read_ot(&ot, &OctreeLimits::default()).unwrap();
    assert_eq!(t2.write_bt(), bytes);
    assert_eq!(t2.write_ot(), ot);
    // message form: node bytes without the header
    let msg = t.to_message_data(true);
    assert_eq!(&bytes[bytes.len() - msg.len()..], &msg[..]);
    let t3 = Octree::from_message_data(true, "OcTree", 0.08, &msg, &OctreeLimits::default()).unwrap();
    assert_eq!(t3.write_bt(), bytes);
}

fn key_of(t: &Octree, p: [f64; 3]) -> OcKey {
    let f = 1.0 / t.resolution();
    [0, 1, 2].map(|i| coord_to_key_axis(p[i], f).unwrap())
}

fn hit(t: &Octree) -> f32 {
    t.sensor_model().log_odds().hit
}

fn miss(t: &Octree) -> f32 {
    t.sensor_model().log_odds().miss
}

#[test]
fn one_hit_makes_a_path_of_seventeen_nodes() {
    let mut t = Octree::new(0.1).unwrap();
    let k = key_of(&t, [0.25, -1.0, 3.0]);
    t.update_key(&k, hit(&t));
    assert_eq!(t.num_nodes(), 17);
    assert_eq!(t.search_key(&k, 16), Some((hit(&t), 16)));
    assert_eq!(t.state_of_key(&k), CellState::Occupied);
    // the root holds the maximum of its children
    assert_eq!(t.search_key(&k, 0), Some((hit(&t), 0)));
    // the neighbour cell is unknown
    assert_eq!(t.state_of_key(&[k[0] + 1, k[1], k[2]]), CellState::Unknown);
    t.update_key(&k, miss(&t));
    let expected = hit(&t) + miss(&t);
    assert_eq!(t.search_key(&k, 16), Some((expected, 16)));
    assert!((expected - 0.441_832_7).abs() < 1e-6);
}

#[test]
fn clamping_stops_at_the_bounds() {
    let mut t = Octree::new(0.1).unwrap();
    let k = key_of(&t, [1.0, 1.0, 1.0]);
    for _ in 0..10 {
        t.update_key(&k, hit(&t));
    }
    // 10 · 0.847 > 3.511: clamped
    assert_eq!(t.search_key(&k, 16).unwrap().0, logodds(0.971));
    for _ in 0..20 {
        t.update_key(&k, miss(&t));
    }
    assert_eq!(t.search_key(&k, 16).unwrap().0, logodds(0.1192));
}

#[test]
fn eight_equal_siblings_prune_and_a_different_update_expands() {
    let mut t = Octree::new(0.1).unwrap();
    let base = key_of(&t, [0.0, 0.0, 0.0]);
    assert_eq!(base, [32768; 3]);
    for i in 0..8 {
        t.update_key(&child_key(&base, 15, i), hit(&t));
    }
    // root + depths 1..15: the eight depth-16 leaves merged into their parent
    assert_eq!(t.num_nodes(), 16);
    assert_eq!(t.search_key(&base, 16), Some((hit(&t), 15)));
    // one child updated again: parent expanded to eight children of value `hit`
    t.update_key(&child_key(&base, 15, 3), miss(&t));
    assert_eq!(t.num_nodes(), 24);
    assert_eq!(
        t.search_key(&child_key(&base, 15, 3), 16),
        Some((hit(&t) + miss(&t), 16))
    );
    assert_eq!(t.search_key(&child_key(&base, 15, 2), 16), Some((hit(&t), 16)));
    assert_eq!(t.search_key(&base, 15), Some((hit(&t), 15)));
}

/// A seeded random tree: hits and misses on keys in a small cube.
pub(crate) fn random_tree(seed: u64, updates: usize, res: f64) -> Octree {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut t = Octree::new(res).unwrap();
    let (h, m) = (hit(&t), miss(&t));
    for _ in 0..updates {
        let k = [0; 3].map(|_| 32768u16 - 20 + rng.random_range(0..40u16));
        t.update_key(&k, if rng.random_bool(0.4) { h } else { m });
    }
    t
}

#[test]
fn generated_trees_round_trip_through_bt_ot_and_messages() {
    for seed in 0..4 {
        let t = random_tree(seed, 3000, 0.05);
        let lim = OctreeLimits::default();
        let ot = t.write_ot();
        let t_ot = Octree::read_ot(&ot, &lim).unwrap();
        assert_eq!(t_ot.write_ot(), ot);
        let bt = t.write_bt();
        let t_bt = Octree::read_bt(&bt, &lim).unwrap();
        assert_eq!(t_bt.write_bt(), bt);
        let full = Octree::from_message_data(false, "OcTree", 0.05, &t.to_message_data(false), &lim).unwrap();
        assert_eq!(full.write_ot(), ot);
        // every cell of the cube keeps its thresholded state in the binary form
        for x in 32748..32788u16 {
            for y in 32748..32788u16 {
                for z in [32748u16, 32760, 32767, 32768, 32787] {
                    assert_eq!(t.state_of_key(&[x, y, z]), t_bt.state_of_key(&[x, y, z]));
                }
            }
        }
    }
}

fn bt_with(size: &str, data: &[u8]) -> Vec<u8> {
    let mut v = format!("{BT_FIRST_LINE}\nid OcTree\nsize {size}\nres 0.1\ndata\n").into_bytes();
    v.extend_from_slice(data);
    v
}

#[test]
fn hostile_streams_get_errors_not_panics() {
    let lim = OctreeLimits::default();
    // 2^20 nested levels claimed: child 0 is inner, again and again
    let nested: Vec<u8> = [3u8, 0].repeat(1 << 20);
    let e = Octree::read_bt(&bt_with("1048576", &nested), &lim);
    assert!(matches!(e, Err(OctreeError::TooDeep { .. })), "{e:?}");
    // wrong size line
    let e = Octree::read_bt(&bt_with("5", &[0b10, 0]), &lim);
    assert_eq!(
        e,
        Err(OctreeError::SizeMismatch {
            declared: 5,
            actual: 2
        })
    );
    // a size beyond the limit is refused before reading
    let e = Octree::read_bt(&bt_with("99999999999999999", &[0b10, 0]), &lim);
    assert!(matches!(e, Err(OctreeError::TooManyNodes { .. })));
    // a size that lies low cannot push the node count past the limit
    let small = OctreeLimits { max_nodes: 100 };
    let full_level: Vec<u8> = [0xffu8, 0xff].repeat(100);
    let e = Octree::read_bt(&bt_with("9", &full_level), &small);
    assert!(
        matches!(e, Err(OctreeError::TooManyNodes { limit: 100, .. })),
        "{e:?}"
    );
    // garbage after the nodes
    let e = Octree::read_bt(&bt_with("2", &[0b10, 0, 7]), &lim);
    assert!(matches!(e, Err(OctreeError::TrailingBytes { extra: 1, .. })));
    // an inner node coded without children
    let e = Octree::read_bt(&bt_with("2", &[0b11, 0, 0, 0]), &lim);
    assert!(matches!(e, Err(OctreeError::BadNodeData { offset, .. }) if offset > 40));
    // .ot with a NaN value
    let mut ot = format!("{OT_FIRST_LINE}\nid OcTree\nsize 1\nres 0.1\ndata\n").into_bytes();
    ot.extend_from_slice(&f32::NAN.to_le_bytes());
    ot.push(0);
    assert!(matches!(
        Octree::read_ot(&ot, &lim),
        Err(OctreeError::BadNodeData { .. })
    ));
    // wrong tree type
    let e = Octree::read_ot(&bt_with("1", &[]), &lim);
    assert!(matches!(e, Err(OctreeError::BadHeader { offset: 0, .. })));
}

#[test]
fn every_truncation_of_a_real_tree_is_an_error() {
    let t = random_tree(9, 800, 0.1);
    let lim = OctreeLimits::default();
    for bytes in [t.write_bt(), t.write_ot()] {
        let ot = bytes.starts_with(OT_FIRST_LINE.as_bytes());
        let read = |b: &[u8]| {
            if ot {
                Octree::read_ot(b, &lim)
            } else {
                Octree::read_bt(b, &lim)
            }
        };
        assert!(read(&bytes).is_ok());
        for cut in 0..bytes.len() {
            let r = read(&bytes[..cut]);
            assert!(r.is_err(), "prefix of {cut} bytes accepted");
        }
    }
}

#[test]
fn random_bytes_never_panic() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let lim = OctreeLimits { max_nodes: 200_000 };
    let mut accepted = 0;
    for trial in 0..300 {
        let n = rng.random_range(0..4000);
        let data: Vec<u8> = (0..n).map(|_| rng.random()).collect();
        let size = rng.random_range(0..5000u32).to_string();
        let r = if trial % 2 == 0 {
            Octree::read_bt(&bt_with(&size, &data), &lim)
        } else {
            let mut v = format!("{OT_FIRST_LINE}\nid OcTree\nsize {size}\nres 0.1\ndata\n").into_bytes();
            v.extend_from_slice(&data);
            Octree::read_ot(&v, &lim)
        };
        accepted += r.is_ok() as usize;
        // and in the message form (no header, no size)
        let _ = Octree::from_message_data(trial % 3 == 0, "OcTree", 0.1, &data, &lim);
    }
    assert!(accepted < 300);
}

#[test]
fn box_volumes_match_a_cell_by_cell_count() {
    use nalgebra::Point3;
    let t = random_tree(3, 4000, 0.1);
    let (min, max) = (Point3::new(-1.23, -0.71, -0.4), Point3::new(0.88, 1.31, 0.52));
    let v = t.volumes_in_box(&min, &max).unwrap();
    // every depth-16 cell the box reaches, weighted by the part of it inside the box
    let (k0, k1) = (t.key_of(&min).unwrap(), t.key_of(&max).unwrap());
    let r = 0.1f64;
    let inside = |k: u16, i: usize| {
        let lo = (k as f64 - 32768.0) * r;
        ((lo + r).min(max[i]) - lo.max(min[i])).max(0.0)
    };
    let (mut f, mut o, mut u) = (0.0, 0.0, 0.0);
    for x in k0[0]..=k1[0] {
        for y in k0[1]..=k1[1] {
            for z in k0[2]..=k1[2] {
                let w = inside(x, 0) * inside(y, 1) * inside(z, 2);
                match t.state_of_key(&[x, y, z]) {
                    CellState::Free => f += w,
                    CellState::Occupied => o += w,
                    CellState::Unknown => u += w,
                }
            }
        }
    }
    assert!(f > 0.0 && o > 0.0 && u > 0.0);
    assert!((v.free - f).abs() < 1e-9, "{} vs {f}", v.free);
    assert!((v.occupied - o).abs() < 1e-9);
    assert!((v.unknown - u).abs() < 1e-9);
    let whole = (0..3).map(|i| max[i] - min[i]).product::<f64>();
    assert!((v.free + v.occupied + v.unknown - whole).abs() < 1e-9);
    // at depth 14 every reported cube is at most 4 cells wide and still covers the box
    let mut n = 0;
    t.for_each_in_box(&min, &max, 14, StateFilter::ALL, |c| {
        assert!(c.depth <= 14);
        n += 1;
    })
    .unwrap();
    assert!(n > 0);
    assert!(t.volumes_in_box(&max, &min).is_err());
}

#[test]
fn state_at_point_and_neighbours_on_a_hand_built_tree() {
    use nalgebra::Point3;
    let mut t = Octree::new(0.5).unwrap();
    let c = t.key_of(&Point3::new(0.1, 0.1, 0.1)).unwrap();
    assert_eq!(c, [32768; 3]);
    t.update_key(&c, hit(&t));
    t.update_key(&[32769, 32768, 32768], miss(&t));
    assert_eq!(
        t.state_at(&Point3::new(0.2, 0.3, 0.4), 16).unwrap().0,
        CellState::Occupied
    );
    assert_eq!(
        t.state_at(&Point3::new(0.7, 0.3, 0.4), 16).unwrap().0,
        CellState::Free
    );
    // at depth 15 both share a parent, which holds the maximum: occupied
    assert_eq!(
        t.state_at(&Point3::new(0.7, 0.3, 0.4), 15).unwrap().0,
        CellState::Occupied
    );
    assert_eq!(
        t.state_at(&Point3::new(-0.2, 0.3, 0.4), 16).unwrap().0,
        CellState::Unknown
    );
    assert!(t.state_at(&Point3::new(1e9, 0.0, 0.0), 16).is_err());
    let n = t.neighbors(&c, 16, false);
    assert_eq!(n.len(), 6);
    let known: Vec<_> = n.iter().filter(|(_, s)| *s != CellState::Unknown).collect();
    assert_eq!(known, vec![&([32769, 32768, 32768], CellState::Free)]);
    assert_eq!(t.neighbors(&c, 16, true).len(), 26);
    let (lo, hi) = t.known_bounds().unwrap();
    assert_eq!((lo, hi), (Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.5, 0.5)));
}

#[test]
fn cached_search_agrees_with_search_from_the_root() {
    use rand::{Rng, SeedableRng};
    let t = random_tree(21, 5000, 0.1);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
    let mut cache = SearchCache::default();
    let mut k = [32768u16; 3];
    for _ in 0..20000 {
        // unit steps (as a DDA takes) mixed with jumps
        if rng.random_bool(0.05) {
            k = [0; 3].map(|_| 32768 - 24 + rng.random_range(0..48u16));
        } else {
            let a = rng.random_range(0..3);
            k[a] = if rng.random_bool(0.5) {
                k[a].wrapping_add(1)
            } else {
                k[a].wrapping_sub(1)
            };
        }
        assert_eq!(t.search_key_cached(&k, &mut cache), t.search_key(&k, 16), "{k:?}");
    }
}

/// Regressions: a tree whose known bounds are the whole key cube (a root with eight
/// leaves) was refused by its own default box, and a box of zero volume, or one
/// ending on a cell boundary, counted a layer of cells beyond its upper faces.
#[test]
fn boxes_on_the_cube_edge_and_on_cell_boundaries_count_exactly() {
    use nalgebra::Point3;
    let lim = OctreeLimits::default();
    // 0x66 0x66: the root's eight children are leaves (binary form)
    let t = Octree::from_message_data(true, "OcTree", 0.1, &[0x66, 0x66], &lim).unwrap();
    let (lo, hi) = t.known_bounds().unwrap();
    let big = 3276.8;
    assert_eq!(
        (lo, hi),
        (Point3::new(-big, -big, -big), Point3::new(big, big, big))
    );
    let v = t.volumes_in_box(&lo, &hi).unwrap();
    // 0x66 = 0b01_10_01_10 per byte: children alternate occupied (01) and free (10)
    let half = (2.0 * big).powi(3) / 2.0;
    assert!((v.free - half).abs() < 1e-9 * half, "{v:?}");
    assert!((v.occupied - half).abs() < 1e-9 * half, "{v:?}");
    assert_eq!(v.unknown, 0.0);
    // zero volume, anywhere
    for p in [Point3::new(0.0, 0.0, 0.0), Point3::new(0.05, -0.13, 0.2)] {
        let v = t.volumes_in_box(&p, &p).unwrap();
        assert_eq!((v.free, v.occupied, v.unknown), (0.0, 0.0, 0.0));
    }
    // a box of exactly one cell, on its boundaries
    let mut one = Octree::new(0.1).unwrap();
    one.update_key(&[32768, 32768, 32768], -1.0);
    let v = one
        .volumes_in_box(&Point3::new(0.0, 0.0, 0.0), &Point3::new(0.1, 0.1, 0.1))
        .unwrap();
    assert!((v.free - 1e-3).abs() < 1e-12, "{v:?}");
    assert!(
        v.unknown.abs() < 1e-12,
        "no cell beyond the box's upper faces: {v:?}"
    );
    assert!(
        t.volumes_in_box(&Point3::new(0.0, 0.0, 0.0), &Point3::new(3276.9, 0.0, 0.0))
            .is_err()
    );
}

/// A ColorOcTree `.ot` (OctoMap's `ColorOcTreeNode` writes its log-odds, then r, g,
/// b, then the child bits) reads as the same occupancy tree as its plain form; the
/// colour file is built here from the plain one by inserting three colour bytes
/// into every 5-byte node record.
#[test]
fn a_color_octree_full_file_reads_as_its_occupancy() {
    let t = random_tree(5, 600, 0.1);
    let plain = t.write_ot();
    let header_end = plain.windows(5).position(|w| w == b"data\n").unwrap() + 5;
    let header = std::str::from_utf8(&plain[..header_end]).unwrap();
    assert!(header.contains("id OcTree\n"));
    let mut color = header.replace("id OcTree\n", "id ColorOcTree\n").into_bytes();
    let nodes = &plain[header_end..];
    assert_eq!(nodes.len() % 5, 0);
    for (i, record) in nodes.chunks_exact(5).enumerate() {
        color.extend_from_slice(&record[..4]);
        color.extend_from_slice(&[i as u8, 7, 200]);
        color.push(record[4]);
    }
    let lim = OctreeLimits::default();
    let back = Octree::read_ot(&color, &lim).unwrap();
    assert_eq!(back.write_ot(), plain);
    // the node bytes alone, as a ROS message carries them
    let color_header = header_end + "Color".len();
    let msg = Octree::from_message_data(false, "ColorOcTree", 0.1, &color[color_header..], &lim).unwrap();
    assert_eq!(msg.write_ot(), plain);
    // cut inside a record: an error, not a panic
    assert!(matches!(
        Octree::read_ot(&color[..color.len() - 3], &lim),
        Err(OctreeError::Truncated { .. })
    ));
}
