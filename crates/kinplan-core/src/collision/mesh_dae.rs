//! COLLADA (`.dae`) mesh files as URDFs name them: the triangles of every
//! geometry the visual scene instances, placed by its nodes' transforms
//! (`matrix`, `translate`, `rotate`, `scale`, composed in document order) and
//! scaled by the document's `<unit meter>` — what assimp, behind pinocchio and
//! MoveIt, loads. Only Z-up documents are read, no external reference is
//! followed, and the XML's size, element count and depth are bounded first.

use std::collections::HashMap;

use nalgebra::{Matrix4, Point3, Unit, Vector3};
use quick_xml::events::{BytesStart, Event};

use super::CollisionError;

/// Elements a COLLADA file may hold (its numbers are text, not elements).
const MAX_ELEMENTS: usize = 200_000;

/// One `<triangles>`, `<polylist>` or `<polygons>` of a geometry.
#[derive(Default)]
struct Primitive {
    /// (semantic, source id, offset) of each `<input>`.
    inputs: Vec<(String, String, usize)>,
    /// Vertices per polygon (`<polylist>`), or `None` (triangles).
    vcount: Option<Vec<usize>>,
    /// Each `<p>`: index tuples, `stride` numbers per vertex.
    p: Vec<Vec<u32>>,
    /// `<polygons>`: every `<p>` is one polygon.
    polygons: bool,
}

/// What the walk over the document collects.
#[derive(Default)]
struct Document {
    unit: f64,
    arrays: HashMap<String, Vec<f64>>,
    /// Source id → (float array id, stride).
    sources: HashMap<String, (String, usize)>,
    /// `<vertices>` id → its POSITION source id.
    vertices: HashMap<String, String>,
    geometries: HashMap<String, Vec<Primitive>>,
    /// (geometry id, node transform) for each `<instance_geometry>`.
    instances: Vec<(String, Matrix4<f64>)>,
    saw_scene: bool,
}

/// The triangles of a COLLADA file (corners in metres), after the checks of
/// the module doc; more than `max_triangles` in all (a geometry instanced by
/// many nodes counts each time) is an error, found before they are held.
/// `field` names the file in errors.
pub(super) fn read_collada(
    bytes: &[u8],
    field: &str,
    max_triangles: usize,
) -> Result<Vec<[Point3<f64>; 3]>, CollisionError> {
    let bad = |reason: String| CollisionError::Parse {
        field: field.to_string(),
        reason,
    };
    let text = std::str::from_utf8(bytes).map_err(|_| bad("a COLLADA file is UTF-8 XML".into()))?;
    let limits = crate::robot::UrdfLimits {
        max_bytes: bytes.len(),
        max_xml_elements: MAX_ELEMENTS,
        ..Default::default()
    };
    crate::robot::prescan(text, &limits).map_err(|e| bad(e.to_string()))?;
    let doc = walk(text).map_err(bad)?;
    let mut out = Vec::new();
    let instances: Vec<(String, Matrix4<f64>)> = if doc.saw_scene {
        doc.instances.clone()
    } else {
        let mut all: Vec<String> = doc.geometries.keys().cloned().collect();
        all.sort();
        all.into_iter().map(|g| (g, Matrix4::identity())).collect()
    };
    for (geometry, transform) in &instances {
        let primitives = doc.geometries.get(geometry).ok_or_else(|| {
            bad(format!(
                "an instance names geometry `{geometry}`, which the file lacks"
            ))
        })?;
        let placed = Matrix4::new_scaling(doc.unit) * transform;
        for prim in primitives {
            triangles_of(&doc, prim, &placed, max_triangles, &mut out).map_err(bad)?;
        }
    }
    Ok(out)
}

fn attr(e: &BytesStart<'_>, name: &str) -> Result<Option<String>, String> {
    match e.try_get_attribute(name) {
        Ok(Some(a)) => a
            .unescape_value()
            .map(|v| Some(v.into_owned()))
            .map_err(|e| e.to_string()),
        Ok(None) => Ok(None),
        Err(e) => Err(e.to_string()),
    }
}

fn local(id: &str) -> Result<String, String> {
    id.strip_prefix('#').map(str::to_string).ok_or_else(|| {
        format!("`{id}` is an external reference; only references inside the file are followed")
    })
}

fn numbers<T: std::str::FromStr>(text: &str, what: &str) -> Result<Vec<T>, String> {
    text.split_ascii_whitespace()
        .map(|w| {
            w.parse()
                .map_err(|_| format!("`{w}` in a <{what}> is not a number"))
        })
        .collect()
}

/// One pass over the XML events, collecting arrays, sources, geometries and
/// the visual scene's instances with their transforms.
fn walk(text: &str) -> Result<Document, String> {
    let mut doc = Document {
        unit: 1.0,
        ..Default::default()
    };
    let mut reader = quick_xml::Reader::from_str(text);
    reader.config_mut().trim_text(true);
    let mut stack: Vec<String> = Vec::new();
    // the element whose text is being read, with its id
    let mut array_id: Option<String> = None;
    let mut source_id: Option<String> = None;
    let mut vertices_id: Option<String> = None;
    let mut geometry_id: Option<String> = None;
    let mut primitive: Option<Primitive> = None;
    // node transforms: the matrix in force at each open <node>
    let mut transforms: Vec<Matrix4<f64>> = Vec::new();
    loop {
        let event = reader.read_event().map_err(|e| format!("XML: {e}"))?;
        let (start, empty) = match &event {
            Event::Start(e) => (Some(e.clone()), false),
            Event::Empty(e) => (Some(e.clone()), true),
            _ => (None, false),
        };
        if let Some(e) = start {
            let name = String::from_utf8_lossy(e.local_name().as_ref()).into_owned();
            match name.as_str() {
                "unit" => {
                    if let Some(m) = attr(&e, "meter")? {
                        doc.unit = m
                            .trim()
                            .parse()
                            .ok()
                            .filter(|v: &f64| v.is_finite() && *v > 0.0)
                            .ok_or_else(|| format!("<unit meter=\"{m}\"> is not a positive number"))?;
                    }
                }
                "float_array" => array_id = attr(&e, "id")?,
                "source" => source_id = attr(&e, "id")?,
                "accessor" => {
                    if let (Some(src), Some(array)) = (source_id.clone(), attr(&e, "source")?) {
                        let stride = attr(&e, "stride")?.and_then(|s| s.parse().ok()).unwrap_or(1);
                        doc.sources.insert(src, (local(&array)?, stride));
                    }
                }
                "vertices" => vertices_id = attr(&e, "id")?,
                "geometry" => {
                    let id = attr(&e, "id")?.unwrap_or_default();
                    doc.geometries.entry(id.clone()).or_default();
                    geometry_id = Some(id);
                }
                "triangles" | "polylist" | "polygons" => {
                    primitive = Some(Primitive {
                        polygons: name == "polygons",
                        vcount: (name == "polylist").then(Vec::new),
                        ..Default::default()
                    });
                }
                "input" => {
                    let semantic = attr(&e, "semantic")?.unwrap_or_default();
                    let source = attr(&e, "source")?.unwrap_or_default();
                    if let Some(prim) = primitive.as_mut() {
                        let offset = attr(&e, "offset")?.and_then(|o| o.parse().ok()).unwrap_or(0);
                        prim.inputs.push((semantic, local(&source)?, offset));
                    } else if let (Some(v), "POSITION") = (vertices_id.clone(), semantic.as_str()) {
                        doc.vertices.insert(v, local(&source)?);
                    }
                }
                "visual_scene" => doc.saw_scene = true,
                "node" => transforms.push(transforms.last().copied().unwrap_or_else(Matrix4::identity)),
                "instance_geometry" => {
                    let url = attr(&e, "url")?.unwrap_or_default();
                    let at = transforms.last().copied().unwrap_or_else(Matrix4::identity);
                    doc.instances.push((local(&url)?, at));
                }
                "instance_node" => {
                    return Err(
                        "<instance_node> is not followed; send the mesh with its nodes inline".into(),
                    );
                }
                _ => {}
            }
            if !empty {
                stack.push(name);
            } else if name == "node" {
                transforms.pop();
            }
            continue;
        }
        match event {
            Event::Text(t) => {
                let content = t.decode().map_err(|e| e.to_string())?;
                let Some(current) = stack.last() else { continue };
                match current.as_str() {
                    "up_axis" if content.trim() != "Z_UP" => {
                        return Err(format!("up axis `{}`: only Z_UP files are read", content.trim()));
                    }
                    "float_array" => {
                        if let Some(id) = &array_id {
                            let values: Vec<f64> = numbers(&content, "float_array")?;
                            doc.arrays.entry(id.clone()).or_default().extend(values);
                        }
                    }
                    "p" => {
                        if let Some(prim) = primitive.as_mut() {
                            prim.p.push(numbers(&content, "p")?);
                        }
                    }
                    "vcount" => {
                        if let Some(Some(v)) = primitive.as_mut().map(|p| p.vcount.as_mut()) {
                            v.extend(numbers::<usize>(&content, "vcount")?);
                        }
                    }
                    "matrix" | "translate" | "rotate" | "scale" if stack.iter().any(|s| s == "node") => {
                        let v: Vec<f64> = numbers(&content, current)?;
                        let m = transform_of(current, &v)?;
                        if let Some(top) = transforms.last_mut() {
                            *top *= m;
                        }
                    }
                    _ => {}
                }
            }
            Event::End(e) => {
                let name = String::from_utf8_lossy(e.local_name().as_ref()).into_owned();
                stack.pop();
                match name.as_str() {
                    "float_array" => array_id = None,
                    "source" => source_id = None,
                    "vertices" => vertices_id = None,
                    "geometry" => geometry_id = None,
                    "triangles" | "polylist" | "polygons" => {
                        if let (Some(prim), Some(g)) = (primitive.take(), geometry_id.as_ref()) {
                            doc.geometries.entry(g.clone()).or_default().push(prim);
                        }
                    }
                    "node" => {
                        transforms.pop();
                    }
                    _ => {}
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    Ok(doc)
}

/// The 4 × 4 transform of a node's `<matrix>` (16 numbers, row-major),
/// `<translate>` (x y z), `<rotate>` (axis x y z, angle in degrees) or
/// `<scale>` (x y z).
fn transform_of(kind: &str, v: &[f64]) -> Result<Matrix4<f64>, String> {
    let need = match kind {
        "matrix" => 16,
        "rotate" => 4,
        _ => 3,
    };
    if v.len() != need || v.iter().any(|x| !x.is_finite()) {
        return Err(format!("<{kind}> needs {need} finite numbers, got {}", v.len()));
    }
    Ok(match kind {
        "matrix" => Matrix4::from_row_slice(v),
        "translate" => Matrix4::new_translation(&Vector3::new(v[0], v[1], v[2])),
        "scale" => Matrix4::new_nonuniform_scaling(&Vector3::new(v[0], v[1], v[2])),
        _ => {
            let axis = Unit::try_new(Vector3::new(v[0], v[1], v[2]), 1e-12)
                .ok_or_else(|| "<rotate> about a zero axis".to_string())?;
            nalgebra::Rotation3::from_axis_angle(&axis, v[3].to_radians()).to_homogeneous()
        }
    })
}

/// The triangles of one primitive, placed by `placed`.
fn triangles_of(
    doc: &Document,
    prim: &Primitive,
    placed: &Matrix4<f64>,
    max_triangles: usize,
    out: &mut Vec<[Point3<f64>; 3]>,
) -> Result<(), String> {
    let Some((_, vertices, offset)) = prim.inputs.iter().find(|(s, _, _)| s == "VERTEX") else {
        return Err("a primitive without a VERTEX input".into());
    };
    let position = doc
        .vertices
        .get(vertices)
        .ok_or_else(|| format!("<vertices> `{vertices}` has no POSITION input"))?;
    let (array, stride) = doc
        .sources
        .get(position)
        .ok_or_else(|| format!("source `{position}` has no accessor"))?;
    if *stride != 3 {
        return Err(format!("positions of stride {stride}; 3 expected"));
    }
    let values = doc
        .arrays
        .get(array)
        .ok_or_else(|| format!("float array `{array}` is missing"))?;
    let per_vertex = prim.inputs.iter().map(|(_, _, o)| o + 1).max().unwrap_or(1);
    let point = |i: u32| -> Result<Point3<f64>, String> {
        let at = 3 * i as usize;
        let p = values
            .get(at..at + 3)
            .ok_or_else(|| format!("vertex index {i} is beyond the {} positions", values.len() / 3))?;
        Ok(placed.transform_point(&Point3::new(p[0], p[1], p[2])))
    };
    let mut fan = |corners: &[u32]| -> Result<(), String> {
        for k in 1..corners.len().saturating_sub(1) {
            if out.len() >= max_triangles {
                return Err(format!(
                    "more than {max_triangles} triangles (the limit of a mesh)"
                ));
            }
            out.push([point(corners[0])?, point(corners[k])?, point(corners[k + 1])?]);
        }
        Ok(())
    };
    for p in &prim.p {
        let corners: Vec<u32> = p
            .chunks(per_vertex)
            .filter_map(|c| c.get(*offset).copied())
            .collect();
        match (&prim.vcount, prim.polygons) {
            (Some(counts), _) => {
                let mut at = 0;
                for &n in counts {
                    let polygon = corners
                        .get(at..at + n)
                        .ok_or("<vcount> asks for more vertices than <p> has")?;
                    fan(polygon)?;
                    at += n;
                }
            }
            (None, true) => fan(&corners)?,
            (None, false) => {
                for t in corners.chunks_exact(3) {
                    fan(t)?;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::mesh_file::tests::{CUBE, FACES};
    use super::*;

    /// A COLLADA document in centimetres: one cube geometry (corners 0/1 on
    /// each axis, triangles with a NORMAL input at offset 1) instanced twice —
    /// by a node translated 100 along x, and by a node (turned 90° about z by
    /// a `<rotate>`) holding a child scaled by 2 — and a quad `<polylist>`.
    fn document(extra_scene: &str, up: &str) -> String {
        let corners: Vec<String> = CUBE.iter().map(|[x, y, z]| format!("{x} {y} {z}")).collect();
        // the 12 triangles, each index followed by a normal index 0
        let p: Vec<String> = FACES.iter().flatten().map(|i| format!("{i} 0")).collect();
        format!(
            r##"<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="centimeter" meter="0.01"/><up_axis>{up}</up_axis></asset>
  <library_geometries>
    <geometry id="cube" name="cube"><mesh>
      <source id="cube-pos"><float_array id="cube-pos-array" count="24">{corners}</float_array>
        <technique_common><accessor source="#cube-pos-array" count="8" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <source id="cube-n"><float_array id="cube-n-array" count="3">0 0 1</float_array>
        <technique_common><accessor source="#cube-n-array" count="1" stride="3"/></technique_common></source>
      <vertices id="cube-v"><input semantic="POSITION" source="#cube-pos"/></vertices>
      <triangles count="12"><input semantic="VERTEX" source="#cube-v" offset="0"/>
        <input semantic="NORMAL" source="#cube-n" offset="1"/><p>{p}</p></triangles>
    </mesh></geometry>
    <geometry id="quad"><mesh>
      <source id="q-pos"><float_array id="q-pos-array" count="12">0 0 5 1 0 5 1 1 5 0 1 5</float_array>
        <technique_common><accessor source="#q-pos-array" count="4" stride="3"/></technique_common></source>
      <vertices id="q-v"><input semantic="POSITION" source="#q-pos"/></vertices>
      <polylist count="1"><input semantic="VERTEX" source="#q-v" offset="0"/><vcount>4</vcount><p>0 1 2 3</p></polylist>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="s">
    <node id="a"><translate>100 0 0</translate><instance_geometry url="#cube"/></node>
    <node id="b"><rotate>0 0 1 90</rotate>
      <node id="c"><scale>2 2 2</scale><instance_geometry url="#cube"/></node>
    </node>
    <node id="d"><instance_geometry url="#quad"/></node>
    {extra_scene}
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>"##,
            corners = corners.join(" "),
            p = p.join(" "),
        )
    }

    #[test]
    fn instanced_geometry_is_placed_by_its_nodes_and_scaled_by_the_unit() {
        let triangles = read_collada(document("", "Z_UP").as_bytes(), "m.dae", 1000).unwrap();
        // 12 + 12 cube triangles, 2 from the fanned quad
        assert_eq!(triangles.len(), 26);
        let near = |a: &Point3<f64>, b: [f64; 3]| (a - Point3::from(b)).norm() < 1e-12;
        // node a: the cube moved 100 cm along x, in metres: x in [1.00, 1.01]
        let a: Vec<&Point3<f64>> = triangles[..12].iter().flatten().collect();
        assert!(
            a.iter()
                .all(|p| (1.0..=1.01 + 1e-12).contains(&p.x) && (0.0..=0.01).contains(&p.y))
        );
        assert!(a.iter().any(|p| near(p, [1.01, 0.01, 0.01])));
        // node b/c: scaled by 2 then turned 90° about z: (x, y, z) → (−2y, 2x, 2z), in cm
        let c: Vec<&Point3<f64>> = triangles[12..24].iter().flatten().collect();
        assert!(c.iter().any(|p| near(p, [-0.02, 0.02, 0.02])));
        assert!(
            c.iter()
                .all(|p| (-0.02 - 1e-12..=1e-12).contains(&p.x) && (-1e-12..=0.02 + 1e-12).contains(&p.y))
        );
        // the quad at z = 5 cm, fanned from its first corner
        assert!(near(&triangles[24][0], [0.0, 0.0, 0.05]) && near(&triangles[25][2], [0.0, 0.01, 0.05]));
    }

    #[test]
    fn what_is_not_followed_or_not_z_up_is_refused_naming_the_file() {
        let refused = |doc: String, what: &str| {
            let e = read_collada(doc.as_bytes(), "arm.dae", 1000)
                .unwrap_err()
                .to_string();
            assert!(e.contains("arm.dae") && e.contains(what), "{e}");
        };
        refused(document("", "Y_UP"), "Z_UP");
        refused(
            document(r#"<node><instance_geometry url="other.dae#g"/></node>"#, "Z_UP"),
            "external",
        );
        refused(
            document(r##"<node><instance_node url="#a"/></node>"##, "Z_UP"),
            "instance_node",
        );
        refused(
            document(r##"<node><instance_geometry url="#nowhere"/></node>"##, "Z_UP"),
            "nowhere",
        );
        let deep = format!(
            "<COLLADA>{}{}</COLLADA>",
            "<node>".repeat(200),
            "</node>".repeat(200)
        );
        refused(deep, "nested");
        refused("<COLLADA><!DOCTYPE".into(), "");
        // one geometry instanced by many nodes: the triangles are counted as they are placed
        let many = "<node><instance_geometry url=\"#cube\"/></node>".repeat(200);
        refused(document(&many, "Z_UP"), "more than 1000 triangles");
    }
}
