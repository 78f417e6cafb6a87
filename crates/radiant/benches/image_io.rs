//! Timings of image I/O, metrics and filter sampling on a 512x512 image.
//! Run: `cargo bench --bench image_io`.

use radiant::color::Rgb;
use radiant::image::{Filter, Image, ImageMeta, compare, exr, pfm, png};
use radiant::math::Vec2;

fn main() {
    divan::main();
}

fn test_image() -> Image {
    let (w, h) = (512, 512);
    let mut img = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            let t = ((x * 7 + y * 13) % 97) as f32 / 97.0;
            img.set(x, y, Rgb::new(t, 0.5 * t + 0.1, (x as f32).sin().abs()));
        }
    }
    img
}

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("radiant-bench-{}-{name}", std::process::id()))
}

#[divan::bench]
fn write_exr_512(b: divan::Bencher) {
    let img = test_image();
    let path = temp("w.exr");
    b.bench(|| exr::write_exr(&path, &img, &ImageMeta::default()).unwrap());
    std::fs::remove_file(&path).ok();
}

#[divan::bench]
fn read_exr_512(b: divan::Bencher) {
    let path = temp("r.exr");
    exr::write_exr(&path, &test_image(), &ImageMeta::default()).unwrap();
    b.bench(|| exr::read_exr(&path).unwrap());
    std::fs::remove_file(&path).ok();
}

#[divan::bench]
fn write_pfm_512(b: divan::Bencher) {
    let img = test_image();
    let path = temp("w.pfm");
    b.bench(|| pfm::write_pfm(&path, &img).unwrap());
    std::fs::remove_file(&path).ok();
}

#[divan::bench]
fn write_png_512(b: divan::Bencher) {
    let img = test_image();
    let path = temp("w.png");
    b.bench(|| png::write_png(&path, &img, 0.0).unwrap());
    std::fs::remove_file(&path).ok();
}

#[divan::bench]
fn metrics_512(b: divan::Bencher) {
    let (a, r) = (test_image(), Image::new(512, 512));
    b.bench(|| compare(&a, &r, None).unwrap());
}

#[divan::bench(args = ["box", "triangle", "gaussian"])]
fn filter_sample_1k(b: divan::Bencher, kind: &str) {
    let f = match kind {
        "box" => Filter::box_filter(Vec2::splat(0.5)),
        "triangle" => Filter::triangle(Vec2::splat(1.0)),
        _ => Filter::default(),
    };
    b.bench(|| {
        let mut acc = 0.0f32;
        for i in 0..1000 {
            let u = Vec2::new(
                (i as f32 + 0.5) / 1000.0,
                ((i * 7919) % 1000) as f32 / 1000.0,
            );
            acc += divan::black_box(&f).sample(u).weight;
        }
        acc
    });
}
