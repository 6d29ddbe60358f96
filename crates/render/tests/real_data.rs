//! Previews of real CMU captures (BVH and ASF/AMC) from the shared corpus; skipped without it.

use image::AnimationDecoder;
use inbetween_io::data::with_shared_data;
use inbetween_render::stick::{render_motion_gif, try_render_motion_frame, StickOptions, DEFAULT_COLORS};

fn near(p: [u8; 3], c: [u8; 3]) -> bool {
    p.iter().zip(c).all(|(&a, b)| (a as i32 - b as i32).abs() <= 2)
}

#[test]
fn cmu_bvh_and_amc_overlay_is_framed_inside_the_image() {
    with_shared_data("render of CMU 01_01", |dir| {
        let cmu = dir.join("mocap/cmu");
        let bvh = inbetween_io::load_motion(&cmu.join("cgspeed/01_01.bvh")).expect("01_01.bvh loads");
        let amc = inbetween_io::load_motion(&cmu.join("asf_amc/01_01.amc")).expect("01_01.amc loads");
        let opts = StickOptions { labels: vec!["bvh".into(), "amc".into()], ..StickOptions::default() };
        let img = try_render_motion_frame(&[&bvh, &amc], 600, &opts).unwrap();
        let (w, h) = img.dimensions();
        for c in &DEFAULT_COLORS[..2] {
            let all = img.enumerate_pixels().filter(|(_, _, p)| near(p.0, *c)).count();
            let edge = img
                .enumerate_pixels()
                .filter(|(x, y, p)| (*x < 4 || *y < 4 || *x >= w - 4 || *y >= h - 4) && near(p.0, *c))
                .count();
            assert!(all > 100, "figure {c:?}: {all} pixels");
            assert_eq!(edge, 0, "figure {c:?} touches the image border");
        }

        let tmp = tempfile::tempdir().unwrap();
        let gif = tmp.path().join("01_01.gif");
        let small = StickOptions { width: 240, height: 180, max_frames: 20, ..StickOptions::default() };
        render_motion_gif(&gif, &[&bvh], &small).unwrap();
        let file = std::io::BufReader::new(std::fs::File::open(&gif).unwrap());
        let frames = image::codecs::gif::GifDecoder::new(file).unwrap().into_frames().collect_frames().unwrap();
        assert_eq!(frames.len(), bvh.num_frames().div_ceil(bvh.num_frames().div_ceil(20)));
        assert!(frames.len() <= 20);
    });
}
