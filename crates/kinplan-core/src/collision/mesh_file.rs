//! Mesh files a robot's URDF names, read from the bytes a client sent with
//! the model — never from disk: STL (binary and ASCII), Wavefront OBJ and
//! COLLADA (`mesh_dae`).
//! Each becomes an [`InlineMesh`] keyed by the URI the URDF writes, with
//! shared vertices merged (STL repeats them per triangle) and every size
//! bounded before it is allocated.

use std::collections::HashMap;

use nalgebra::Point3;

use super::CollisionError;
use super::model::InlineMesh;

/// Bounds on one mesh file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MeshFileLimits {
    /// Largest file, bytes. Default 32 MiB.
    pub max_bytes: usize,
    /// Most triangles. Default 400,000 (the scene limit of a mesh).
    pub max_triangles: usize,
    /// Most distinct vertices. Default 200,000.
    pub max_vertices: usize,
}

impl Default for MeshFileLimits {
    fn default() -> Self {
        Self {
            max_bytes: 32 << 20,
            max_triangles: 400_000,
            max_vertices: 200_000,
        }
    }
}

/// Reads the mesh file `uri` (as the URDF names it) from `bytes`. The format
/// follows the extension: `.stl` (binary when its size is exactly
/// `84 + 50·n` for the `n` its header gives, else ASCII `solid … facet …
/// vertex x y z`), `.obj` (`v x y z`, `f i j k …` with 1-based or negative
/// indices, `i/t/n` forms; polygons fanned into triangles), `.dae` (the
/// geometries a Z-up COLLADA scene instances, placed by their nodes and
/// scaled by its unit).
///
/// ```
/// use kinplan_core::collision::{MeshFileLimits, read_mesh_file};
/// let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n";
/// let m = read_mesh_file("package://arm/tetra.obj", obj, &MeshFileLimits::default()).unwrap();
/// assert_eq!((m.vertices.len(), m.indices.len()), (4, 12));
/// assert!(read_mesh_file("hand.dae", b"<COLLADA/>", &MeshFileLimits::default()).is_err()); // no triangles
/// ```
pub fn read_mesh_file(
    uri: &str,
    bytes: &[u8],
    limits: &MeshFileLimits,
) -> Result<InlineMesh, CollisionError> {
    let field = || format!("meshes[{uri}]");
    if bytes.len() > limits.max_bytes {
        return Err(CollisionError::TooLarge {
            field: field(),
            value: bytes.len() as f64,
            limit: limits.max_bytes as f64,
        });
    }
    let path = uri.split(['?', '#']).next().unwrap_or(uri).to_ascii_lowercase();
    let mut mesh = Builder::new(limits, field());
    if path.ends_with(".stl") {
        if is_binary_stl(bytes) {
            read_binary_stl(bytes, &mut mesh)?;
        } else {
            read_ascii_stl(bytes, &mut mesh)?;
        }
    } else if path.ends_with(".obj") {
        read_obj(bytes, &mut mesh)?;
    } else if path.ends_with(".dae") {
        let triangles = super::mesh_dae::read_collada(bytes, &field(), limits.max_triangles)?;
        mesh.expect_triangles(triangles.len())?;
        for t in triangles {
            let corners = [
                mesh.vertex(t[0].coords.into())?,
                mesh.vertex(t[1].coords.into())?,
                mesh.vertex(t[2].coords.into())?,
            ];
            mesh.triangle(corners)?;
        }
    } else {
        return Err(CollisionError::Parse {
            field: field(),
            reason: "unknown mesh format: the file name must end in .stl, .obj or .dae".into(),
        });
    }
    mesh.finish(uri)
}

/// Whether `bytes` are a binary STL: a triangle count at byte 80 that gives
/// exactly the file's size.
fn is_binary_stl(bytes: &[u8]) -> bool {
    bytes.len() >= 84
        && u32::from_le_bytes(bytes[80..84].try_into().expect("4 bytes")) as u64 * 50 + 84
            == bytes.len() as u64
}

fn read_binary_stl(bytes: &[u8], mesh: &mut Builder<'_>) -> Result<(), CollisionError> {
    let count = (bytes.len() - 84) / 50;
    mesh.expect_triangles(count)?;
    for t in 0..count {
        let at = 84 + 50 * t + 12; // after the facet normal
        let mut corner = [0u32; 3];
        for (k, c) in corner.iter_mut().enumerate() {
            let f = |i: usize| {
                let o = at + 12 * k + 4 * i;
                f32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes")) as f64
            };
            *c = mesh.vertex([f(0), f(1), f(2)])?;
        }
        mesh.triangle(corner)?;
    }
    Ok(())
}

fn read_ascii_stl(bytes: &[u8], mesh: &mut Builder<'_>) -> Result<(), CollisionError> {
    let text = std::str::from_utf8(bytes).map_err(|_| {
        mesh.error("neither a binary STL (its size does not match its triangle count) nor ASCII text")
    })?;
    if !text.trim_start().starts_with("solid") {
        return Err(mesh.error("an ASCII STL starts with `solid`"));
    }
    let mut corners = Vec::with_capacity(3);
    let mut words = text.split_ascii_whitespace();
    while let Some(word) = words.next() {
        if word != "vertex" {
            continue;
        }
        let mut xyz = [0.0; 3];
        for v in &mut xyz {
            *v = words
                .next()
                .and_then(|w| w.parse::<f64>().ok())
                .ok_or_else(|| mesh.error("`vertex` needs three numbers"))?;
        }
        corners.push(mesh.vertex(xyz)?);
        if corners.len() == 3 {
            mesh.triangle([corners[0], corners[1], corners[2]])?;
            corners.clear();
        }
    }
    if !corners.is_empty() {
        return Err(mesh.error("a facet with fewer than three vertices"));
    }
    Ok(())
}

fn read_obj(bytes: &[u8], mesh: &mut Builder<'_>) -> Result<(), CollisionError> {
    let text = std::str::from_utf8(bytes).map_err(|_| mesh.error("an OBJ file is UTF-8 text"))?;
    // OBJ indices refer to `v` lines in file order, duplicates included
    let mut ids: Vec<u32> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_ascii_whitespace();
        match words.next() {
            Some("v") => {
                let mut xyz = [0.0; 3];
                for v in &mut xyz {
                    *v = words
                        .next()
                        .and_then(|w| w.parse::<f64>().ok())
                        .ok_or_else(|| mesh.error(&format!("line {}: `v` needs three numbers", n + 1)))?;
                }
                ids.push(mesh.vertex(xyz)?);
            }
            Some("f") => {
                let mut face: Vec<u32> = Vec::with_capacity(4);
                for w in words {
                    let index: i64 = w
                        .split('/')
                        .next()
                        .and_then(|i| i.parse().ok())
                        .ok_or_else(|| mesh.error(&format!("line {}: bad face index `{w}`", n + 1)))?;
                    let at = if index > 0 {
                        index - 1
                    } else {
                        ids.len() as i64 + index
                    };
                    let id = usize::try_from(at).ok().and_then(|i| ids.get(i)).ok_or_else(|| {
                        mesh.error(&format!("line {}: face index {index} names no vertex", n + 1))
                    })?;
                    face.push(*id);
                }
                if face.len() < 3 {
                    return Err(mesh.error(&format!("line {}: a face needs three vertices", n + 1)));
                }
                for k in 1..face.len() - 1 {
                    mesh.triangle([face[0], face[k], face[k + 1]])?;
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Collects merged vertices and triangles within the limits.
struct Builder<'a> {
    limits: &'a MeshFileLimits,
    field: String,
    vertices: Vec<Point3<f64>>,
    index_of: HashMap<[u64; 3], u32>,
    indices: Vec<u32>,
}

impl<'a> Builder<'a> {
    fn new(limits: &'a MeshFileLimits, field: String) -> Self {
        Self {
            limits,
            field,
            vertices: Vec::new(),
            index_of: HashMap::new(),
            indices: Vec::new(),
        }
    }

    fn error(&self, reason: &str) -> CollisionError {
        CollisionError::Parse {
            field: self.field.clone(),
            reason: reason.to_string(),
        }
    }

    fn expect_triangles(&mut self, count: usize) -> Result<(), CollisionError> {
        if count > self.limits.max_triangles {
            return Err(CollisionError::TooMany {
                field: self.field.clone(),
                count,
                limit: self.limits.max_triangles,
            });
        }
        self.indices.reserve(3 * count);
        Ok(())
    }

    /// The index of the vertex at `xyz` (merged with an equal one), refusing
    /// non-finite coordinates and more vertices than the limit.
    fn vertex(&mut self, xyz: [f64; 3]) -> Result<u32, CollisionError> {
        if xyz.iter().any(|v| !v.is_finite()) {
            return Err(CollisionError::NonFinite {
                field: self.field.clone(),
            });
        }
        // +0.0 and −0.0 are one point
        let key = xyz.map(|v| (v + 0.0).to_bits());
        if let Some(&i) = self.index_of.get(&key) {
            return Ok(i);
        }
        if self.vertices.len() >= self.limits.max_vertices {
            return Err(CollisionError::TooMany {
                field: self.field.clone(),
                count: self.vertices.len() + 1,
                limit: self.limits.max_vertices,
            });
        }
        let i = self.vertices.len() as u32;
        self.vertices.push(Point3::new(xyz[0], xyz[1], xyz[2]));
        self.index_of.insert(key, i);
        Ok(i)
    }

    fn triangle(&mut self, corners: [u32; 3]) -> Result<(), CollisionError> {
        if self.indices.len() / 3 >= self.limits.max_triangles {
            return Err(CollisionError::TooMany {
                field: self.field.clone(),
                count: self.indices.len() / 3 + 1,
                limit: self.limits.max_triangles,
            });
        }
        self.indices.extend_from_slice(&corners);
        Ok(())
    }

    fn finish(self, uri: &str) -> Result<InlineMesh, CollisionError> {
        if self.indices.is_empty() {
            return Err(CollisionError::Degenerate {
                field: self.field,
                reason: "the mesh has no triangles".into(),
            });
        }
        Ok(InlineMesh {
            filename: uri.to_string(),
            vertices: self.vertices,
            indices: self.indices,
        })
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The unit cube `[0, 1]³` as 12 triangles over its 8 corners.
    pub(in crate::collision) const CUBE: [[f64; 3]; 8] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [0.0, 1.0, 1.0],
        [1.0, 1.0, 1.0],
    ];
    pub(in crate::collision) const FACES: [[usize; 3]; 12] = [
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];

    fn binary_stl() -> Vec<u8> {
        let mut b = vec![b's'; 80]; // a header that starts like ASCII, as some writers do
        b.extend_from_slice(&(FACES.len() as u32).to_le_bytes());
        for f in FACES {
            b.extend_from_slice(&[0u8; 12]);
            for v in f {
                for c in CUBE[v] {
                    b.extend_from_slice(&(c as f32).to_le_bytes());
                }
            }
            b.extend_from_slice(&[0, 0]);
        }
        b
    }

    fn ascii_stl() -> Vec<u8> {
        let mut s = String::from("solid cube\n");
        for f in FACES {
            s += " facet normal 0 0 0\n  outer loop\n";
            for v in f {
                let [x, y, z] = CUBE[v];
                s += &format!("   vertex {x:e} {y} {z}\n");
            }
            s += "  endloop\n endfacet\n";
        }
        s += "endsolid cube\n";
        s.into_bytes()
    }

    /// The quads of the cube as an OBJ with `i/t/n` indices and a negative one.
    fn obj() -> Vec<u8> {
        let mut s = String::from("# cube\no cube\n");
        for [x, y, z] in CUBE {
            s += &format!("v {x} {y} {z}\nvn 0 0 1\n");
        }
        for q in [
            [1, 3, 4, 2],
            [5, 6, 8, 7],
            [1, 2, 6, 5],
            [3, 7, 8, 4],
            [1, 5, 7, 3],
            [2, 4, 8, 6],
        ] {
            s += &format!("f {}/1/1 {}//1 {} -{}\n", q[0], q[1], q[2], 9 - q[3]);
        }
        s.into_bytes()
    }

    /// The cube's corners as the mesh holds them, each triangle as its three
    /// corners, sorted: the same for every format.
    fn corners_of(m: &InlineMesh) -> (Vec<[i64; 3]>, usize) {
        let mut v: Vec<[i64; 3]> = m
            .vertices
            .iter()
            .map(|p| [p.x, p.y, p.z].map(|c| c as i64))
            .collect();
        v.sort();
        (v, m.indices.len() / 3)
    }

    #[test]
    fn every_format_reads_the_unit_cube() {
        let lim = MeshFileLimits::default();
        let want: Vec<[i64; 3]> = {
            let mut v: Vec<[i64; 3]> = CUBE.iter().map(|p| p.map(|c| c as i64)).collect();
            v.sort();
            v
        };
        for (uri, bytes) in [
            ("package://arm/meshes/cube.STL", binary_stl()),
            ("meshes/cube.stl", ascii_stl()),
            ("file:///opt/arm/cube.obj", obj()),
        ] {
            let m = read_mesh_file(uri, &bytes, &lim).unwrap();
            assert_eq!(m.filename, uri);
            assert_eq!(corners_of(&m), (want.clone(), 12), "{uri}");
            assert!(m.indices.iter().all(|i| (*i as usize) < m.vertices.len()));
        }
    }

    #[test]
    fn bad_files_are_errors_naming_the_uri() {
        let lim = MeshFileLimits::default();
        let named = |e: CollisionError| {
            assert!(
                e.to_string().contains("meshes[x.stl]") || e.to_string().contains("meshes[x.obj]"),
                "{e}"
            )
        };
        // truncated binary STL: its size no longer matches, and it is not ASCII
        let cut = binary_stl()[..200].to_vec();
        named(read_mesh_file("x.stl", &cut, &lim).unwrap_err());
        // NaN vertex
        let mut nan = binary_stl();
        nan[84 + 12..84 + 16].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(matches!(
            read_mesh_file("x.stl", &nan, &lim),
            Err(CollisionError::NonFinite { .. })
        ));
        // empty, and a face naming no vertex
        named(read_mesh_file("x.stl", b"solid empty\nendsolid\n", &lim).unwrap_err());
        named(read_mesh_file("x.obj", b"v 0 0 0\nf 1 2 3\n", &lim).unwrap_err());
        // a 10^7-triangle header is refused before anything is read
        let mut huge = vec![0u8; 84];
        huge[80..84].copy_from_slice(&10_000_000u32.to_le_bytes());
        huge.resize(84 + 50 * 1000, 0);
        assert!(read_mesh_file("x.stl", &huge, &lim).is_err());
        let mut claims = vec![0u8; 84 + 50 * 500_000];
        claims[80..84].copy_from_slice(&500_000u32.to_le_bytes());
        assert!(matches!(
            read_mesh_file("x.stl", &claims, &lim),
            Err(CollisionError::TooMany { .. })
        ));
        let small = MeshFileLimits {
            max_bytes: 100,
            ..lim
        };
        assert!(matches!(
            read_mesh_file("x.stl", &binary_stl(), &small),
            Err(CollisionError::TooLarge { .. })
        ));
        assert!(read_mesh_file("x.ply", b"ply", &lim).is_err());
    }
}
