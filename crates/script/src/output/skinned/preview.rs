//! A software check of the skin: a story frame with every skinned body painted from its texture.

use super::*;

/// A body's colour lookup: its texture (wrapping like glTF's default REPEAT sampler) or its base
/// colour.
struct Paint {
    texture: Option<image::RgbaImage>,
    base: [f32; 4],
}

impl Paint {
    fn of(body: &SkinnedBody) -> Paint {
        let texture = body.image.as_ref().and_then(|i| image::load_from_memory(&i.bytes).ok()).map(|i| i.to_rgba8());
        Paint { texture, base: body.base_color }
    }

    fn at(&self, uv: [f32; 2]) -> [u8; 3] {
        let lin_to_srgb = |c: f32| {
            (255.0 * if c <= 0.003_130_8 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 })
                .round()
                .clamp(0.0, 255.0) as u8
        };
        let base = [0, 1, 2].map(|k| lin_to_srgb(self.base[k]));
        let Some(t) = &self.texture else { return base };
        let (w, h) = (t.width() as f32, t.height() as f32);
        let x = ((uv[0].rem_euclid(1.0) * w) as u32).min(t.width() - 1);
        let y = ((uv[1].rem_euclid(1.0) * h) as u32).min(t.height() - 1);
        let p = t.get_pixel(x, y).0;
        [0, 1, 2].map(|k| (p[k] as f32 * self.base[k].clamp(0.0, 1.0)).round() as u8)
    }
}

/// Story frame `frame` seen through `camera(frame)`: room, boxes and every skinned body (its
/// triangles coloured from the texture at their centre, Lambert-shaded), everything painted far
/// to near; characters without a body are left out. A check of the skin, not a renderer.
pub fn render_skinned_frame(cast: &SkinnedCast, frame: usize, size: (u32, u32)) -> RgbImage {
    let SkinnedCast { scene, cat, characters, bodies, camera, fps } = *cast;
    let c = camera(frame);
    let cam =
        Camera3::new(c.eye.as_dvec3(), c.target.as_dvec3(), DVec3::Y, c.fovy_deg as f64).with_viewport(size.0, size.1);
    let mut cv = Canvas::new(size.0, size.1, [246, 247, 250]);
    draw_room(&mut cv, &cam, scene);
    let light = Vec3::new(0.4, 1.0, 0.6).normalize();
    // (depth, object index | triangle in pixels and its colour)
    type Item = (f64, Result<usize, ([(f32, f32); 3], [u8; 3])>);
    let mut items: Vec<Item> = Vec::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let c = crate::layout::geom::center(o);
        let p = DVec3::new(c[0] as f64, (o.position[1] + o.size[1] / 2.0) as f64, c[1] as f64);
        items.push((cam.to_camera(p).z, Ok(i)));
    }
    let t = frame as f64 / fps;
    for ((_, m), body) in characters.iter().zip(bodies) {
        let Some(body) = body else { continue };
        let f = ((t / m.frame_time()).round().max(0.0) as usize).min(m.num_frames().saturating_sub(1));
        let world = joint_matrices(&forward(m.skeleton(), &m.pose(f)));
        let pts = skin_positions(body, &world);
        let paint = Paint::of(body);
        for tri in body.indices.chunks_exact(3) {
            let tri = [tri[0], tri[1], tri[2]];
            let [a, b, c] = tri.map(|v| pts[v as usize]);
            let n = (b - a).cross(c - a).normalize_or_zero();
            let centre = (a + b + c) / 3.0;
            if n.dot(cam.eye.as_vec3() - centre) <= 0.0 {
                continue;
            }
            let (Some(pa), Some(pb), Some(pc)) =
                (cam.project(a.as_dvec3()), cam.project(b.as_dvec3()), cam.project(c.as_dvec3()))
            else {
                continue;
            };
            let depth = cam.to_camera(centre.as_dvec3()).z;
            let shade = 0.6 + 0.4 * n.dot(light).max(0.0);
            // Texture detail: the triangle split 4 × 4 (in pixels and uv alike), each piece
            // coloured at its centre.
            let px = [(pa.0, pa.1), (pb.0, pb.1), (pc.0, pc.1)];
            let uv = tri.map(|v| body.uvs[v as usize]);
            for (sub, suv) in inbetween_render::subdivide_triangle(px, uv, 2) {
                let c = [0, 1].map(|k| (suv[0][k] + suv[1][k] + suv[2][k]) / 3.0);
                items.push((depth, Err((sub, scale_color(paint.at(c), shade)))));
            }
        }
    }
    items.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (_, item) in items {
        match item {
            Ok(i) => {
                let o = &scene.objects[i];
                draw_object(&mut cv, &cam, o, cat);
            }
            Err((tri, colour)) => cv.fill_convex(&tri, colour),
        }
    }
    cv.into_image()
}
