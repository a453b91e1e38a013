//! Reading an embedded surface from a gmsh 4.1 file (`[fluid.embedded] surface = { file = .. }`,
//! format: [`interface_protocol::io::gmsh`]): its linear triangles and quads are the surface
//! elements; points and lines are skipped; volume elements are refused (a surface is wanted).
//! Nodes no element uses are dropped. A zero-area element is an error naming its line.

use super::generate::SurfaceMesh;
use interface_protocol::io::gmsh::{self, ElementType, GmshError, Shape};
use interface_protocol::messages::SurfaceElement;
use std::path::Path;

/// Reads the surface mesh in `path`.
pub fn read(path: &Path) -> Result<SurfaceMesh, GmshError> {
    let msh = gmsh::read(path, accept)?;
    from_msh(&msh)
}

/// Parses the bytes of a surface mesh named `origin`.
pub fn parse(bytes: &[u8], origin: &str) -> Result<SurfaceMesh, GmshError> {
    from_msh(&gmsh::parse(bytes, origin, accept)?)
}

fn accept(t: ElementType) -> Result<(), String> {
    match (t.shape, t.order) {
        (Shape::Triangle | Shape::Quadrangle, 1) | (Shape::Point | Shape::Line, _) => Ok(()),
        _ => Err(format!(
            "element type {} ({}) is not a surface element: an embedded surface is made of linear triangles (2) and quadrangles (3)",
            t.code,
            t.shape.name()
        )),
    }
}

fn from_msh(msh: &gmsh::Msh) -> Result<SurfaceMesh, GmshError> {
    let mut slot = vec![u32::MAX; msh.coords.len()];
    let mut s = SurfaceMesh::default();
    for block in msh.blocks.iter().filter(|b| b.kind.shape.dim() == 2) {
        for (ids, &at) in block.elements().zip(&block.positions) {
            let p: Vec<[f64; 3]> = ids.iter().map(|&i| msh.coords[i as usize]).collect();
            let area = polygon_area(&p);
            let size = p.iter().map(|q| dist(*q, p[0])).fold(0.0, f64::max);
            if area.is_nan() || area <= 1e-12 * size * size {
                return Err(msh.error(
                    at,
                    format!(
                        "{} with nodes {:?} has zero area: its corners are repeated or in a line",
                        block.kind.shape.name(),
                        ids.iter().map(|&i| msh.node_tags[i as usize]).collect::<Vec<_>>()
                    ),
                ));
            }
            let mut nodes = [0u32; 4];
            for (k, &i) in ids.iter().enumerate() {
                if slot[i as usize] == u32::MAX {
                    slot[i as usize] = s.x.len() as u32;
                    s.x.push(msh.coords[i as usize]);
                }
                nodes[k] = slot[i as usize];
            }
            let n_nodes = ids.len() as u8;
            s.elements.push(SurfaceElement { nodes, n_nodes, ..Default::default() });
        }
    }
    if s.elements.is_empty() {
        return Err(msh.error(
            msh.end,
            "the file has no triangles or quadrangles: an embedded surface needs at least one",
        ));
    }
    Ok(s)
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Area of a planar polygon: half the norm of `Σ p_k × p_{k+1}`.
fn polygon_area(p: &[[f64; 3]]) -> f64 {
    let mut c = [0.0; 3];
    for k in 0..p.len() {
        let (a, b) = (p[k], p[(k + 1) % p.len()]);
        c[0] += a[1] * b[2] - a[2] * b[1];
        c[1] += a[2] * b[0] - a[0] * b[2];
        c[2] += a[0] * b[1] - a[1] * b[0];
    }
    0.5 * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn msh(elements: &str) -> String {
        format!(
            "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 5 1 5\n2 1 0 5\n1\n2\n3\n4\n5\n\
             0 0 0\n1 0 0\n1 1 0\n0 1 0\n9 9 9\n$EndNodes\n$Elements\n{elements}$EndElements\n"
        )
    }

    #[test]
    fn triangles_and_quads_are_read_and_unused_nodes_dropped() {
        let text = msh("2 2 1 2\n2 1 2 1\n1 1 2 3\n2 2 3 1\n2 1 2 3 4\n");
        let s = parse(text.as_bytes(), "plate.msh").unwrap();
        assert_eq!(s.x.len(), 4, "node 5 is unused");
        assert_eq!(s.elements.len(), 2);
        assert_eq!((s.elements[0].n_nodes, s.elements[1].n_nodes), (3, 4));
        assert_eq!(&s.elements[1].nodes, &[0, 1, 2, 3]);
    }

    #[test]
    fn degenerate_and_volume_elements_name_the_line() {
        let text = msh("1 1 1 1\n2 1 2 1\n7 1 2 2\n");
        let e = parse(text.as_bytes(), "plate.msh").unwrap_err().to_string();
        assert!(e.contains("plate.msh:21") && e.contains("zero area"), "{e}");
        let text = msh("1 1 1 1\n3 1 4 1\n1 1 2 3 5\n");
        let e = parse(text.as_bytes(), "plate.msh").unwrap_err().to_string();
        assert!(e.contains("plate.msh:") && e.contains("not a surface element"), "{e}");
    }
}
