//! Planar polygons in their own frame: the signed area of a ring in `(u, v)` metres and the frame
//! of a polygon given by its 3-D vertices (Newell's normal, the first edge as `u`, planarity and
//! simplicity checked). A leaf module: the `[room]` table's validation (`description`) refuses
//! polygons with it and `ibl-room`'s face builder lays them out with it.

use glam::{Vec2, Vec3};

/// The signed area of a 2D polygon (positive counter-clockwise).
pub fn signed_area(points: &[Vec2]) -> f32 {
    let n = points.len();
    0.5 * (0..n)
        .map(|i| points[i].perp_dot(points[(i + 1) % n]))
        .sum::<f32>()
}

/// The frame of a planar polygon: origin (its first vertex), unit axes `u` (along the first
/// edge) and `v`, front normal `u x v` (Newell's normal, so the given winding is
/// counter-clockwise seen from the front), and the vertices in `(u, v)` metres. Refuses
/// polygons out of plane by more than 1 mm plus 1e-4 of their size, with no area, or whose edges
/// cross.
pub fn polygon_frame(vertices: &[[f32; 3]]) -> Result<(Vec3, Vec3, Vec3, Vec3, Vec<Vec2>), String> {
    let p: Vec<Vec3> = vertices.iter().map(|&v| Vec3::from(v)).collect();
    let n = p.len();
    // Newell's method: robust for any simple planar polygon.
    let mut newell = Vec3::ZERO;
    for i in 0..n {
        let (a, b) = (p[i], p[(i + 1) % n]);
        newell += Vec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let extent = p
        .iter()
        .map(|&q| (q - p[0]).length())
        .fold(0.0f32, f32::max);
    if newell.length() < 1e-6 * extent.max(1e-3).powi(2) || extent < 1e-3 {
        return Err("has no area".into());
    }
    let normal = newell.normalize();
    let tolerance = 1e-3 + 1e-4 * extent;
    if let Some(k) = p
        .iter()
        .position(|&q| (q - p[0]).dot(normal).abs() > tolerance)
    {
        return Err(format!(
            "vertex {k} lies {:.4} m off the polygon's plane (tolerance {tolerance:.4} m)",
            (p[k] - p[0]).dot(normal).abs()
        ));
    }
    let first_edge = (1..n)
        .map(|i| p[i] - p[0])
        .find(|e| e.cross(normal).length() > 1e-4)
        .ok_or("has no area")?;
    let u_axis = (first_edge - normal * first_edge.dot(normal)).normalize();
    let v_axis = normal.cross(u_axis);
    let points: Vec<Vec2> = p
        .iter()
        .map(|&q| Vec2::new((q - p[0]).dot(u_axis), (q - p[0]).dot(v_axis)))
        .collect();
    if signed_area(&points) <= 1e-6 {
        return Err("has no area".into());
    }
    for i in 0..n {
        for j in i + 1..n {
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            if !adjacent
                && segments_cross(
                    points[i],
                    points[(i + 1) % n],
                    points[j],
                    points[(j + 1) % n],
                )
            {
                return Err(format!(
                    "edges {i} and {j} cross (the polygon is not simple)"
                ));
            }
        }
    }
    Ok((p[0], u_axis, v_axis, normal, points))
}

/// Whether segments `ab` and `cd` intersect (touching counts).
fn segments_cross(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> bool {
    let orient = |p: Vec2, q: Vec2, r: Vec2| (q - p).perp_dot(r - p);
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: Vec2, q: Vec2, r: Vec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}
