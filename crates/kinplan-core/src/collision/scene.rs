//! The obstacles a robot moves among, as plain domain values, and their
//! validation. A [`Scene`] only exists validated: every number finite,
//! every size positive and bounded, every mesh index in range and every
//! triangle non-degenerate.

use nalgebra::{Isometry3, Point3, Vector3};

use super::CollisionError;

/// The geometry of one obstacle, in the obstacle's own frame (metres).
/// Cylinders and capsules run along z and are centred on the origin, as in
/// URDF and MoveIt.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    /// Half extents along x, y, z.
    Box {
        half_extents: Vector3<f64>,
    },
    Sphere {
        radius: f64,
    },
    /// Radius and full length along z.
    Cylinder {
        radius: f64,
        length: f64,
    },
    /// Radius and the distance between the two cap centres, along z.
    Capsule {
        radius: f64,
        length: f64,
    },
    /// A triangle mesh: `indices` holds three vertex indices per triangle
    /// (counter-clockwise seen from outside; only used for contact normals).
    Mesh {
        vertices: Vec<Point3<f64>>,
        indices: Vec<u32>,
    },
    /// Occupied axis-aligned cubes of edge `size`, centred at `centers`
    /// (in the obstacle frame): the extension point for an occupancy octree,
    /// whose occupied leaves (and, on request, unknown ones) become cells.
    OccupiedCells {
        size: f64,
        centers: Vec<Point3<f64>>,
    },
}

/// One obstacle: a named geometry placed by `pose` (obstacle frame in the
/// robot's base frame).
#[derive(Debug, Clone, PartialEq)]
pub struct Obstacle {
    pub name: String,
    pub pose: Isometry3<f64>,
    pub geometry: Geometry,
}

impl Obstacle {
    pub fn new(name: impl Into<String>, pose: Isometry3<f64>, geometry: Geometry) -> Self {
        Obstacle {
            name: name.into(),
            pose,
            geometry,
        }
    }
}

/// Bounds on what a scene may hold, so a request cannot ask for unbounded
/// work or memory. Sizes in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneLimits {
    /// Obstacles in one scene.
    pub max_obstacles: usize,
    /// Vertices of one mesh.
    pub max_mesh_vertices: usize,
    /// Triangles of one mesh.
    pub max_mesh_triangles: usize,
    /// Triangles over all meshes plus occupied cells, i.e. broad-phase leaves.
    pub max_total_elements: usize,
    /// Largest |coordinate| of a pose, vertex or cell centre, and largest size.
    pub max_coordinate: f64,
}

impl Default for SceneLimits {
    fn default() -> Self {
        SceneLimits {
            max_obstacles: 10_000,
            max_mesh_vertices: 200_000,
            max_mesh_triangles: 400_000,
            max_total_elements: 2_000_000,
            max_coordinate: 1.0e3,
        }
    }
}

/// A validated set of obstacles (see the module doc).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scene {
    obstacles: Vec<Obstacle>,
}

impl Scene {
    /// The empty scene.
    pub fn empty() -> Self {
        Scene::default()
    }

    /// Validates `obstacles` against `limits`. Errors name the field as
    /// `obstacles[i].…` with the offending numbers.
    pub fn new(obstacles: Vec<Obstacle>, limits: &SceneLimits) -> Result<Self, CollisionError> {
        if obstacles.len() > limits.max_obstacles {
            return Err(CollisionError::TooMany {
                field: "obstacles".into(),
                count: obstacles.len(),
                limit: limits.max_obstacles,
            });
        }
        let mut total = 0usize;
        for (i, o) in obstacles.iter().enumerate() {
            let field = format!("obstacles[{i}]");
            check_pose(&o.pose, &field, limits)?;
            total += validate_geometry(&o.geometry, &field, limits)?;
            if total > limits.max_total_elements {
                return Err(CollisionError::TooMany {
                    field: "obstacles (triangles and cells)".into(),
                    count: total,
                    limit: limits.max_total_elements,
                });
            }
        }
        Ok(Scene { obstacles })
    }

    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    pub fn is_empty(&self) -> bool {
        self.obstacles.is_empty()
    }
}

fn check_pose(p: &Isometry3<f64>, field: &str, limits: &SceneLimits) -> Result<(), CollisionError> {
    let t = &p.translation.vector;
    let q = p.rotation.quaternion().coords;
    if t.iter().chain(q.iter()).any(|v| !v.is_finite()) {
        return Err(CollisionError::NonFinite {
            field: format!("{field}.pose"),
        });
    }
    if t.amax() > limits.max_coordinate {
        return coordinate(t.amax(), &format!("{field}.pose.position"), limits);
    }
    Ok(())
}

fn coordinate(value: f64, field: &str, limits: &SceneLimits) -> Result<(), CollisionError> {
    if value.abs() > limits.max_coordinate {
        return Err(CollisionError::TooLarge {
            field: field.into(),
            value,
            limit: limits.max_coordinate,
        });
    }
    Ok(())
}

/// A size: finite, > 0 and within the coordinate limit. The field's name is
/// made by `field` only for an error (a scene's many sizes format no text).
pub(crate) fn positive(
    value: f64,
    field: impl FnOnce() -> String,
    limits: &SceneLimits,
) -> Result<(), CollisionError> {
    if value.is_finite() && value > 0.0 && value <= limits.max_coordinate {
        return Ok(());
    }
    let field = field();
    if !value.is_finite() {
        return Err(CollisionError::NonFinite { field });
    }
    if value <= 0.0 {
        return Err(CollisionError::NotPositive { field, value });
    }
    coordinate(value, &field, limits)
}

/// Validates one geometry; returns how many broad-phase elements it adds
/// (triangles or cells; 1 for a primitive).
fn validate_geometry(g: &Geometry, field: &str, limits: &SceneLimits) -> Result<usize, CollisionError> {
    match g {
        Geometry::Box { half_extents } => {
            for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                positive(
                    half_extents[k],
                    || format!("{field}.box.half_extents.{axis}"),
                    limits,
                )?;
            }
            Ok(1)
        }
        Geometry::Sphere { radius } => {
            positive(*radius, || format!("{field}.sphere.radius"), limits).map(|_| 1)
        }
        Geometry::Cylinder { radius, length } => {
            positive(*radius, || format!("{field}.cylinder.radius"), limits)?;
            positive(*length, || format!("{field}.cylinder.length"), limits).map(|_| 1)
        }
        Geometry::Capsule { radius, length } => {
            positive(*radius, || format!("{field}.capsule.radius"), limits)?;
            // A capsule of length 0 is a sphere: allowed.
            if !length.is_finite() {
                return Err(CollisionError::NonFinite {
                    field: format!("{field}.capsule.length"),
                });
            }
            if *length < 0.0 {
                return Err(CollisionError::NotPositive {
                    field: format!("{field}.capsule.length"),
                    value: *length,
                });
            }
            coordinate(*length, &format!("{field}.capsule.length"), limits).map(|_| 1)
        }
        Geometry::Mesh { vertices, indices } => validate_mesh(vertices, indices, field, limits),
        Geometry::OccupiedCells { size, centers } => {
            positive(*size, || format!("{field}.cells.size"), limits)?;
            if centers.len() > limits.max_total_elements {
                return Err(CollisionError::TooMany {
                    field: format!("{field}.cells.centers"),
                    count: centers.len(),
                    limit: limits.max_total_elements,
                });
            }
            for (k, c) in centers.iter().enumerate() {
                point(c, &format!("{field}.cells.centers[{k}]"), limits)?;
            }
            Ok(centers.len())
        }
    }
}

fn point(p: &Point3<f64>, field: &str, limits: &SceneLimits) -> Result<(), CollisionError> {
    if p.iter().any(|v| !v.is_finite()) {
        return Err(CollisionError::NonFinite { field: field.into() });
    }
    coordinate(p.coords.amax(), field, limits)
}

/// Mesh checks: sizes within limits, finite vertices, `indices.len()` a
/// multiple of 3, every index `< vertices.len()`, and no degenerate triangle
/// (a repeated index, or area `½|(b−a)×(c−a)| ≤ 1e-12 m²`).
pub(crate) fn validate_mesh(
    vertices: &[Point3<f64>],
    indices: &[u32],
    field: &str,
    limits: &SceneLimits,
) -> Result<usize, CollisionError> {
    let triangles = validate_mesh_points(vertices, indices, field, limits)?;
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| vertices[i as usize]);
        let area = 0.5 * (b - a).cross(&(c - a)).norm();
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] || area <= 1e-12 {
            return Err(CollisionError::Degenerate {
                field: format!("{field}.indices[{}..{}]", 3 * t, 3 * t + 3),
                reason: format!("triangle {t} has area {area:.3e} m²"),
            });
        }
    }
    Ok(triangles)
}

/// [`validate_mesh`] without the degenerate-triangle test: what a mesh used
/// as its convex hull needs (a robot mesh file's zero-area slivers change no
/// hull).
pub(crate) fn validate_mesh_points(
    vertices: &[Point3<f64>],
    indices: &[u32],
    field: &str,
    limits: &SceneLimits,
) -> Result<usize, CollisionError> {
    if vertices.is_empty() {
        return Err(CollisionError::Empty {
            field: format!("{field}.vertices"),
        });
    }
    if indices.is_empty() {
        return Err(CollisionError::Empty {
            field: format!("{field}.indices"),
        });
    }
    if vertices.len() > limits.max_mesh_vertices {
        return Err(CollisionError::TooMany {
            field: format!("{field}.vertices"),
            count: vertices.len(),
            limit: limits.max_mesh_vertices,
        });
    }
    if !indices.len().is_multiple_of(3) {
        return Err(CollisionError::Degenerate {
            field: format!("{field}.indices"),
            reason: format!("{} indices is not a multiple of 3", indices.len()),
        });
    }
    let triangles = indices.len() / 3;
    if triangles > limits.max_mesh_triangles {
        return Err(CollisionError::TooMany {
            field: format!("{field}.indices (triangles)"),
            count: triangles,
            limit: limits.max_mesh_triangles,
        });
    }
    for (k, v) in vertices.iter().enumerate() {
        point(v, &format!("{field}.vertices[{k}]"), limits)?;
    }
    for (k, &i) in indices.iter().enumerate() {
        if i as usize >= vertices.len() {
            return Err(CollisionError::IndexOutOfRange {
                field: format!("{field}.indices[{k}]"),
                index: i,
                vertex_count: vertices.len(),
            });
        }
    }
    Ok(triangles)
}
