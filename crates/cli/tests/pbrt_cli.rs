//! pbrt-v4's command line: `radiant scene.pbrt [more.pbrt]` without a subcommand and
//! each pbrt flag (--quick, --log-level, --write-partial-images, --mse-reference-*,
//! --stats, --display-server, --aov, `Film "gbuffer"`), end to end.

use std::collections::HashMap;
use std::io::Read;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

use radiant::image::read_image;
use radiant_report::tev::Packet;

mod common;
use common::*;

fn ok(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("radiant runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A diffuse wall of reflectance (0.25, 0.5, 0.75) filling the view in the plane z = 5,
/// seen from the origin along +z (camera space = world space), lit by a point light.
const WALL_OPTIONS: &str = "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 30\n\
     Sampler \"independent\" \"integer pixelsamples\" 8\n";
const WALL_WORLD: &str = "WorldBegin\nLightSource \"point\" \"rgb I\" [ 10 10 10 ] \"point3 from\" [ 0 0 0 ]\n\
     Material \"diffuse\" \"rgb reflectance\" [ 0.25 0.5 0.75 ]\n\
     Shape \"trianglemesh\" \"point3 P\" [ -20 -20 5  20 -20 5  20 20 5  -20 20 5 ]\n\
     \"integer indices\" [ 0 1 2  0 2 3 ]\n";

fn write_scene(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The EXR's channels by name.
fn exr_channels(path: &Path) -> HashMap<String, Vec<f32>> {
    let image = exr::prelude::read_all_flat_layers_from_file(path).expect("EXR reads");
    let layer = &image.layer_data[0];
    layer
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
        .collect()
}

#[test]
fn a_scene_file_renders_without_a_subcommand() {
    let dir = temp_dir("bare");
    let scene = write_scene(
        &dir,
        "wall.pbrt",
        &format!(
            "Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 12\n{WALL_OPTIONS}{WALL_WORLD}"
        ),
    );
    let out = dir.join("x.exr");
    ok(radiant()
        .arg(&scene)
        .args(["--spp", "4", "--nthreads", "2", "--outfile"])
        .arg(&out));
    let img = read_image(&out).unwrap();
    assert_eq!((img.width, img.height), (16, 12));
    assert!(img.mean() > 0.0);
    // Subcommands still work, and a file named like one is reached by its path.
    ok(radiant().args(["compare"]).arg(&out).arg(&out));
    let named = write_scene(&dir, "render", &std::fs::read_to_string(&scene).unwrap());
    let out2 = dir.join("y.exr");
    ok(radiant()
        .arg(Path::new(".").join("render"))
        .current_dir(&dir)
        .args(["--spp", "1", "--quiet", "-o"])
        .arg(&out2));
    assert!(named.exists() && out2.exists());
}

#[test]
fn several_files_are_read_as_one_scene_with_their_own_locations() {
    let dir = temp_dir("multi");
    let a = write_scene(
        &dir,
        "a.pbrt",
        &format!(
            "Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n{WALL_OPTIONS}"
        ),
    );
    let b = write_scene(&dir, "b.pbrt", WALL_WORLD);
    let out = dir.join("ab.exr");
    ok(radiant()
        .arg(&a)
        .arg(&b)
        .args(["--spp", "2", "--quiet", "-o"])
        .arg(&out));
    assert_eq!(read_image(&out).unwrap().width, 8);
    // An error in the second file names that file, line and column.
    let bad = write_scene(&dir, "bad.pbrt", "WorldBegin\n  Shapo \"sphere\"\n");
    let o = radiant()
        .arg(&a)
        .arg(&bad)
        .args(["-o"])
        .arg(dir.join("bad.exr"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("bad.pbrt:2:3"), "{stderr}");
}

#[test]
fn quick_quarters_the_resolution_and_takes_one_sample() {
    let dir = temp_dir("quick");
    let out = dir.join("q.exr");
    ok(radiant()
        .args([
            "cornell-box",
            "--quick",
            "--spp",
            "64",
            "--resolution",
            "40x32",
            "-o",
        ])
        .arg(&out));
    let img = read_image(&out).unwrap();
    assert_eq!((img.width, img.height), (10, 8));
    let spp = radiant::image::exr::read_exr_attributes(&out)
        .unwrap()
        .samples_per_pixel;
    assert_eq!(spp, Some(1));
}

#[test]
fn log_levels_choose_the_messages() {
    let dir = temp_dir("log");
    let scene = write_scene(
        &dir,
        "warn.pbrt",
        &format!(
            "Film \"spectral\" \"integer xresolution\" 8 \"integer yresolution\" 8\n{WALL_OPTIONS}{WALL_WORLD}"
        ),
    );
    let stderr = |level: &str| {
        let out = ok(radiant()
            .arg(&scene)
            .args(["--spp", "4", "--log-level", level, "-o"])
            .arg(dir.join(format!("{level}.exr"))));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let verbose = stderr("verbose");
    let error = stderr("error");
    let fatal = stderr("fatal");
    assert!(verbose.contains("pass done: 4 spp"), "{verbose}");
    assert!(verbose.contains("Film \"spectral\""), "{verbose}");
    assert!(
        error.contains("Film \"spectral\"") && !error.contains("pass done"),
        "{error}"
    );
    assert!(fatal.trim().is_empty(), "{fatal}");
}

#[test]
fn partial_images_are_written_after_every_pass() {
    let dir = temp_dir("partial");
    let out_path = dir.join("p.exr");
    let out = ok(radiant()
        .args([
            "cornell-box",
            "--spp",
            "8",
            "--resolution",
            "16x16",
            "--write-partial-images",
            "--log-level",
            "verbose",
            "-o",
        ])
        .arg(&out_path));
    let stderr = String::from_utf8_lossy(&out.stderr);
    // Passes of 1, 1, 2 and 4 samples.
    let partial: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("partial image"))
        .collect();
    assert_eq!(partial.len(), 4, "{stderr}");
    assert!(partial[3].ends_with("(8 spp)"), "{stderr}");
    assert!(read_image(&out_path).unwrap().mean() > 0.0);
}

#[test]
fn mse_reference_output_has_pbrts_format_and_falls() {
    let dir = temp_dir("mse");
    let reference = dir.join("ref.exr");
    ok(radiant()
        .args([
            "cornell-box",
            "--spp",
            "256",
            "--resolution",
            "16x16",
            "--quiet",
            "-o",
        ])
        .arg(&reference));
    let mse_path = dir.join("mse.txt");
    ok(radiant()
        .args([
            "cornell-box",
            "--spp",
            "64",
            "--resolution",
            "16x16",
            "--quiet",
        ])
        .arg("--mse-reference-image")
        .arg(&reference)
        .arg("--mse-reference-out")
        .arg(&mse_path)
        .arg("-o")
        .arg(dir.join("test.exr")));
    let text = std::fs::read_to_string(&mse_path).unwrap();
    // pbrt-v4's "%d, %.9g" lines: samples per pixel, mean squared error.
    let rows: Vec<(u32, f64)> = text
        .lines()
        .map(|l| {
            let (spp, mse) = l.split_once(", ").expect("SPP, MSE");
            (spp.parse().unwrap(), mse.trim().parse().unwrap())
        })
        .collect();
    let spps: Vec<u32> = rows.iter().map(|r| r.0).collect();
    assert_eq!(spps, [1, 2, 4, 8, 16, 32, 64], "{text}");
    assert!(rows.iter().all(|r| r.1.is_finite() && r.1 > 0.0), "{text}");
    // Monte Carlo error falls as 1/spp: over 64x it must fall well below a quarter.
    assert!(rows[6].1 < rows[0].1 / 4.0, "{text}");
    // The last line is the MSE of the written image.
    let test = read_image(dir.join("test.exr")).unwrap();
    let r = read_image(&reference).unwrap();
    let mse: f64 = test
        .pixels
        .iter()
        .zip(&r.pixels)
        .flat_map(|(a, b)| {
            a.to_array()
                .into_iter()
                .zip(b.to_array())
                .map(|(x, y)| (x as f64 - y as f64).powi(2))
        })
        .sum::<f64>()
        / (3.0 * test.pixels.len() as f64);
    assert!(
        (rows[6].1 - mse).abs() <= 1e-6 * mse,
        "{} vs {mse}",
        rows[6].1
    );
}

#[test]
fn stats_count_rays_by_kind_and_leave_the_image_alone() {
    let dir = temp_dir("stats");
    let plain = dir.join("plain.exr");
    let counted = dir.join("counted.exr");
    let args = [
        "cornell-box",
        "--spp",
        "4",
        "--resolution",
        "16x16",
        "--quiet",
        "-o",
    ];
    ok(radiant().args(args).arg(&plain));
    let out = ok(radiant().args(args).arg(&counted).arg("--stats"));
    assert_eq!(
        read_image(&plain).unwrap().pixels,
        read_image(&counted).unwrap().pixels
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let value = |name: &str| -> u64 {
        let line = stdout
            .lines()
            .find(|l| l.trim_start().starts_with(name))
            .unwrap_or_else(|| panic!("no {name} in {stdout}"));
        line.split_whitespace().last().unwrap().parse().unwrap()
    };
    // One camera ray per pixel sample (the pinhole always makes one).
    assert_eq!(value("Camera rays"), 16 * 16 * 4, "{stdout}");
    assert!(
        value("Indirect rays") > 0 && value("Shadow rays") > 0,
        "{stdout}"
    );
    assert_eq!(value("Photon rays"), 0, "{stdout}");
    assert_eq!(
        value("Closest-hit tests"),
        value("Camera rays") + value("Indirect rays"),
        "{stdout}"
    );
    for section in ["Memory", "Film", "Time", "Rendering"] {
        assert!(stdout.contains(section), "{section}: {stdout}");
    }
    // Photon mapping reports its photons.
    let out = ok(radiant()
        .args([
            "cornell-box",
            "--integrator",
            "photonmap",
            "--spp",
            "1",
            "--resolution",
            "8x8",
            "--quiet",
            "--stats",
            "-o",
        ])
        .arg(dir.join("pm.exr")));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("Photons stored"), "{stdout}");
    let photon_rays = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("Photon rays"))
        .and_then(|l| l.split_whitespace().last()?.parse::<u64>().ok())
        .unwrap();
    assert!(photon_rays > 0, "{stdout}");
}

/// Reads tev packets from one connection until the client hangs up.
fn record_tev(listener: TcpListener) -> Vec<Packet> {
    let (mut stream, _) = listener.accept().unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(60)))
        .unwrap();
    let mut packets = Vec::new();
    loop {
        let mut len = [0u8; 4];
        if stream.read_exact(&mut len).is_err() {
            break;
        }
        let n = u32::from_le_bytes(len) as usize;
        let mut bytes = len.to_vec();
        bytes.resize(n, 0);
        stream.read_exact(&mut bytes[4..]).unwrap();
        packets.push(Packet::decode(&bytes).expect("a packet tev accepts"));
    }
    packets
}

#[test]
fn display_server_streams_the_render_to_tev() {
    let dir = temp_dir("tev");
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap().to_string();
    let server = std::thread::spawn(move || record_tev(listener));
    let out_path = dir.join("live.exr");
    ok(radiant()
        .args([
            "cornell-box",
            "--spp",
            "4",
            "--resolution",
            "40x24",
            "--quiet",
        ])
        .args(["--display-server", &addr, "-o"])
        .arg(&out_path));
    let packets = server.join().unwrap();
    let Packet::CreateImage {
        name,
        width,
        height,
        channels,
        ..
    } = &packets[0]
    else {
        panic!("first packet {:?}", packets[0]);
    };
    assert_eq!((name.as_str(), *width, *height), ("live.exr", 40, 24));
    assert_eq!(channels, &["R", "G", "B"]);
    assert_eq!(
        packets.last(),
        Some(&Packet::CloseImage {
            name: "live.exr".into()
        })
    );
    // Updates after each pass (1, 1, 2 spp) and of the final image: each covers the
    // image in tiles; the last set of tiles is the written image.
    let updates: Vec<&Packet> = packets
        .iter()
        .filter(|p| matches!(p, Packet::UpdateImage { .. }))
        .collect();
    let covered: i64 = updates
        .iter()
        .map(|p| match p {
            Packet::UpdateImage { width, height, .. } => (*width as i64) * (*height as i64),
            _ => 0,
        })
        .sum();
    assert_eq!(covered, 4 * 40 * 24, "3 passes and the final image");
    let image = read_image(&out_path).unwrap();
    let mut shown = vec![[0f32; 3]; 40 * 24];
    let last_tiles = updates.len() / 4;
    for p in &updates[updates.len() - last_tiles..] {
        if let Packet::UpdateImage {
            x,
            y,
            width,
            height,
            data,
            ..
        } = p
        {
            for j in 0..*height {
                for i in 0..*width {
                    let k = (j * width + i) as usize;
                    let at = ((y + j) * 40 + x + i) as usize;
                    shown[at] = [data[0][k], data[1][k], data[2][k]];
                }
            }
        }
    }
    let written: Vec<[f32; 3]> = image.pixels.iter().map(|p| p.to_array()).collect();
    assert_eq!(shown, written);
}

#[test]
fn a_viewer_that_goes_away_does_not_stop_the_render() {
    let dir = temp_dir("tev-gone");
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap().to_string();
    // Accepts, reads the first packet, hangs up.
    let server = std::thread::spawn(move || {
        let (mut stream, _) = listener.accept().unwrap();
        let mut first = [0u8; 16];
        let _ = stream.read(&mut first);
    });
    let out_path = dir.join("gone.exr");
    ok(radiant()
        .args([
            "cornell-box",
            "--spp",
            "16",
            "--resolution",
            "64x64",
            "--quiet",
        ])
        .args(["--display-server", &addr, "-o"])
        .arg(&out_path));
    server.join().unwrap();
    assert!(read_image(&out_path).unwrap().mean() > 0.0);
    // Nobody listening at all: a warning, and the render goes on.
    let free = TcpListener::bind("127.0.0.1:0").unwrap();
    let dead = free.local_addr().unwrap().to_string();
    drop(free);
    let out = ok(radiant()
        .args(["cornell-box", "--spp", "1", "--resolution", "8x8"])
        .args(["--display-server", &dead, "-o"])
        .arg(dir.join("dead.exr")));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--display-server"));
}

#[test]
fn gbuffer_film_writes_albedo_normals_position_and_depth() {
    let dir = temp_dir("gbuffer");
    let scene = write_scene(
        &dir,
        "wall.pbrt",
        &format!(
            "Film \"gbuffer\" \"integer xresolution\" 12 \"integer yresolution\" 8 \
             \"string coordinatesystem\" \"world\"\n{WALL_OPTIONS}{WALL_WORLD}"
        ),
    );
    let out = dir.join("g.exr");
    ok(radiant().arg(&scene).args(["--quiet", "-o"]).arg(&out));
    let ch = exr_channels(&out);
    let mut names: Vec<&str> = ch.keys().map(String::as_str).collect();
    names.sort();
    assert_eq!(
        names,
        [
            "Albedo.B",
            "Albedo.G",
            "Albedo.R",
            "B",
            "G",
            "N.X",
            "N.Y",
            "N.Z",
            "Ns.X",
            "Ns.Y",
            "Ns.Z",
            "P.X",
            "P.Y",
            "P.Z",
            "R",
            "Variance.B",
            "Variance.G",
            "Variance.R",
            "Z"
        ]
    );
    let all = |name: &str, want: f32| {
        for (i, v) in ch[name].iter().enumerate() {
            assert!((v - want).abs() < 1e-4, "{name}[{i}] = {v}, want {want}");
        }
    };
    // A diffuse wall's albedo is its reflectance, for every sample.
    all("Albedo.R", 0.25);
    all("Albedo.G", 0.5);
    all("Albedo.B", 0.75);
    // Its normal: pbrt's triangle normal, cross(p0 - p2, p1 - p2) = +z.
    all("N.X", 0.0);
    all("N.Y", 0.0);
    all("N.Z", 1.0);
    all("Ns.Z", 1.0);
    // Every point of the plane z = 5, at camera-space depth 5.
    all("P.Z", 5.0);
    all("Z", 5.0);
    // The image itself is still read as R, G, B.
    let image = read_image(&out).unwrap();
    assert!(image.mean() > 0.0);
    for (i, v) in ch["Variance.G"].iter().enumerate() {
        assert!(v.is_finite() && *v >= 0.0, "Variance.G[{i}] = {v}");
    }
}

#[test]
fn variance_channels_match_the_spread_of_independent_renders() {
    // The variance channel of a 64-spp render estimates each pixel's per-sample
    // variance; two 1-spp renders with other seeds are two independent samples per
    // pixel, so over the image half their mean squared difference estimates the same
    // mean variance (E[(a-b)^2] = 2 Var). 1024 pixels: agreement within a factor 2.
    let dir = temp_dir("variance");
    let render = |seed: &str, spp: &str, extra: &[&str], name: &str| {
        let p = dir.join(name);
        ok(radiant()
            .args(["cornell-box", "--resolution", "32x32", "--quiet"])
            .args(["--seed", seed, "--spp", spp])
            .args(extra)
            .arg("-o")
            .arg(&p));
        p
    };
    let v = render("1", "64", &["--aov", "variance"], "v.exr");
    let ch = exr_channels(&v);
    let g = &ch["Variance.G"];
    let var_mean = g.iter().map(|&x| x as f64).sum::<f64>() / g.len() as f64;
    let a = read_image(render("2", "1", &[], "a.exr")).unwrap();
    let b = read_image(render("3", "1", &[], "b.exr")).unwrap();
    let half_msd: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(x, y)| ((x.g - y.g) as f64).powi(2))
        .sum::<f64>()
        / (2.0 * a.pixels.len() as f64);
    let ratio = var_mean / half_msd;
    assert!(
        (0.5..2.0).contains(&ratio),
        "variance {var_mean} vs spread {half_msd}"
    );
    // SPPM keeps no per-sample moments: a warning, no channels.
    let out = ok(radiant()
        .args([
            "cornell-box",
            "--integrator",
            "sppm",
            "--spp",
            "1",
            "--resolution",
            "8x8",
        ])
        .args(["--aov", "variance", "-o"])
        .arg(dir.join("s.exr")));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no variance channels"));
}

#[test]
fn aov_flag_adds_the_channels_asked_for_to_any_film() {
    let dir = temp_dir("aov");
    let out = dir.join("c.exr");
    ok(radiant()
        .args([
            "cornell-box",
            "--spp",
            "4",
            "--resolution",
            "16x16",
            "--quiet",
        ])
        .args(["--aov", "albedo,depth", "-o"])
        .arg(&out));
    let ch = exr_channels(&out);
    let mut names: Vec<&str> = ch.keys().map(String::as_str).collect();
    names.sort();
    assert_eq!(
        names,
        ["Albedo.B", "Albedo.G", "Albedo.R", "B", "G", "R", "Z"]
    );
    // The Cornell box's walls and blocks are diffuse with reflectances below one, and
    // the camera sees something in every pixel.
    assert!(ch["Albedo.G"].iter().all(|&a| a > 0.0 && a < 1.0));
    assert!(ch["Z"].iter().all(|&z| z > 0.0));
    // The image is the one rendered without AOVs.
    let plain = dir.join("plain.exr");
    ok(radiant()
        .args([
            "cornell-box",
            "--spp",
            "4",
            "--resolution",
            "16x16",
            "--quiet",
            "-o",
        ])
        .arg(&plain));
    assert_eq!(
        read_image(&plain).unwrap().pixels,
        read_image(&out).unwrap().pixels
    );
    // AOVs need EXR.
    let o = radiant()
        .args(["cornell-box", "--aov", "albedo", "-o"])
        .arg(dir.join("c.png"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
}
