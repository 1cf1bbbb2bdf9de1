//! The kernels' device functions (the matrix products and vertex transform, clip-space
//! classification, clipping, fixed-point setup, barycentrics, depth, texture sampling with every
//! wrap mode and filter) compiled as host C++ and compared bit for bit with the Rust core on
//! thousands of random inputs. Every `_rn` CUDA intrinsic the kernels use is a correctly
//! rounded IEEE operation, as x86-64's SSE arithmetic is, so agreement here means the GPU
//! computes the CPU's coverage and depth (what is left for a run on a GPU: the compiler and the
//! hardware keeping that promise — `gpu-check.sh`).
//!
//! Needs a C++ compiler (`$CXX`, else `c++`); skips without one unless `KANTELE_REQUIRE` names
//! `cxx`.

use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

use glam::{Mat4, Quat, Vec2, Vec3, Vec4};
use kantele::geometry::clip::{classify, ClipPolygon, ClipTest, ClipVertex, GuardBand};
use kantele::setup::{setup_triangle, CullMode, FrontFace, SetupReject, TriangleSetup, Viewport};
use kantele::shade::texture::{Filter, MinFilter, Sampler, Texture, Wrap};
use kantele::MAX_VARYINGS;
use kantele_cuda::defines::{define_options, MATERIAL_VARYINGS};
use kantele_cuda::records::{filter_code, min_filter_code, wrap_code};

const NV: usize = MATERIAL_VARYINGS;

fn required() -> bool {
    std::env::var("KANTELE_REQUIRE")
        .map(|v| v.split([',', ' ']).any(|s| s == "cxx"))
        .unwrap_or(false)
}

/// The harness, compiled once for all tests of this file (tests run in parallel threads: each
/// compiling to the same path would replace the executable while another test runs it).
fn build_harness() -> Option<PathBuf> {
    static HARNESS: std::sync::OnceLock<Result<Option<PathBuf>, String>> =
        std::sync::OnceLock::new();
    match HARNESS.get_or_init(compile_harness) {
        Ok(path) => path.clone(),
        Err(message) => panic!("{message}"),
    }
}

fn compile_harness() -> Result<Option<PathBuf>, String> {
    let cxx = std::env::var("CXX").unwrap_or_else(|_| "c++".into());
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/host");
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("kantele-cuda-host-harness");
    let result = Command::new(&cxx)
        .args([
            "-std=c++17",
            "-O2",
            "-ffp-contract=off",
            "-fno-fast-math",
            "-Wall",
        ])
        .args(define_options())
        .arg(dir.join("harness.cpp"))
        .arg("-o")
        .arg(&out)
        .output();
    match result {
        Ok(o) if o.status.success() => Ok(Some(out)),
        Ok(o) => Err(format!(
            "the kernels' common.cuh does not compile as host C++:\n{}",
            String::from_utf8_lossy(&o.stderr)
        )),
        Err(e) if required() => Err(format!("KANTELE_REQUIRE=cxx but {cxx} cannot run: {e}")),
        Err(e) => {
            kantele_testkit::report_skip(format!("no C++ compiler ({cxx}: {e})"));
            Ok(None)
        }
    }
}

/// xorshift64*: a small deterministic generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

struct Case {
    width: u32,
    height: u32,
    cull_back: bool,
    front_cw: bool,
    pos: [Vec4; 3],
    varyings: [[f32; NV]; 3],
}

fn random_case(rng: &mut Rng) -> Case {
    let sizes = [
        (64, 64),
        (301, 203),
        (1920, 1080),
        (1, 1),
        (16384, 7),
        (8, 8),
    ];
    let (width, height) = sizes[rng.below(sizes.len() as u64) as usize];
    let kind = rng.below(6);
    let mut pos = [Vec4::ZERO; 3];
    for p in pos.iter_mut() {
        let w = match kind {
            4 => rng.range(-1.0, 2.0),
            _ => rng.range(0.2, 3.0),
        };
        let (x, y) = match kind {
            1 => {
                // On the half-pixel lattice, so edges pass through pixel centres.
                let px = rng.below(2 * width as u64 + 2) as f32 * 0.5 - 0.5;
                let py = rng.below(2 * height as u64 + 2) as f32 * 0.5 - 0.5;
                (
                    px / width as f32 * 2.0 - 1.0,
                    1.0 - py / height as f32 * 2.0,
                )
            }
            4 => (rng.range(-1e6, 1e6), rng.range(-1e6, 1e6)),
            _ => (rng.range(-1.3, 1.3), rng.range(-1.3, 1.3)),
        };
        let z = match kind {
            2 | 3 => rng.range(-3.0, 1.0),
            _ => rng.range(-1.1, 1.1),
        };
        *p = Vec4::new(x * w, y * w, z * w, w);
    }
    if kind == 5 {
        // Collinear: the third vertex between the first two.
        pos[2] = pos[0] + (pos[1] - pos[0]) * 0.5;
    }
    let mut varyings = [[0.0; NV]; 3];
    for v in varyings.iter_mut().flatten() {
        *v = rng.range(-2.0, 2.0);
    }
    Case {
        width,
        height,
        cull_back: rng.below(2) == 0,
        front_cw: rng.below(4) == 0,
        pos,
        varyings,
    }
}

fn hex(v: f32) -> String {
    format!("{:08x}", v.to_bits())
}

fn input_line(c: &Case) -> String {
    let g = GuardBand::new(c.width, c.height);
    let mut s = format!(
        "T {} {} {} {} {} {} {} {}",
        c.width,
        c.height,
        c.cull_back as u32,
        c.front_cw as u32,
        hex(g.k_x),
        hex(g.k_y),
        hex(c.width as f32 * 0.5),
        hex(c.height as f32 * 0.5)
    );
    for i in 0..3 {
        for v in c.pos[i].to_array() {
            s.push(' ');
            s.push_str(&hex(v));
        }
        for v in c.varyings[i] {
            s.push(' ');
            s.push_str(&hex(v));
        }
    }
    s.push('\n');
    s
}

fn print_setup(out: &mut String, r: Result<TriangleSetup, SetupReject>) {
    let t = match r {
        Ok(t) => t,
        Err(SetupReject::Culled) => {
            out.push_str("S 1\n");
            return;
        }
        Err(SetupReject::Degenerate) => {
            out.push_str("S 2\n");
            return;
        }
    };
    out.push_str(&format!(
        "S 0 area {} bbox {} {} {} {} ff {} sw {}",
        t.area2,
        t.bbox.x0,
        t.bbox.y0,
        t.bbox.x1,
        t.bbox.y1,
        t.front_facing() as u8,
        t.swapped() as u8
    ));
    for e in t.edges {
        out.push_str(&format!(" e {} {} {} {}", e.a, e.b, e.c, e.bias));
    }
    for i in 0..3 {
        out.push_str(&format!(
            " v {} {} {} {}",
            t.pos_subpixel[i][0],
            t.pos_subpixel[i][1],
            hex(t.depth[i]),
            hex(t.inv_w[i])
        ));
    }
    let g = t.bary_gradient;
    out.push_str(&format!(
        " r {} {} g {} {} {} {}\n",
        hex(t.depth_range[0]),
        hex(t.depth_range[1]),
        hex(g[0][0]),
        hex(g[0][1]),
        hex(g[1][0]),
        hex(g[1][1])
    ));
    let b = t.bbox;
    let xs = [b.x0, b.x1 - 1, (b.x0 + b.x1) / 2];
    let ys = [b.y0, b.y1 - 1, (b.y0 + b.y1) / 2];
    for k in 0..3 {
        let bary = t.barycentrics(xs[k], ys[k]);
        out.push_str(&format!(
            "P {} {} {} {} {} {} {}\n",
            xs[k],
            ys[k],
            t.covers(xs[k], ys[k]) as u8,
            hex(bary[0]),
            hex(bary[1]),
            hex(bary[2]),
            hex(t.depth_at(&bary))
        ));
    }
}

/// What the Rust core does with a case, in the harness' output format.
fn rust_output(c: &Case) -> String {
    let vp = Viewport::new(c.width, c.height);
    let guard = GuardBand::new(c.width, c.height);
    let cull = if c.cull_back {
        CullMode::Back
    } else {
        CullMode::None
    };
    let front = if c.front_cw {
        FrontFace::Cw
    } else {
        FrontFace::Ccw
    };
    let mut out = String::new();
    let test = classify(c.pos, &guard);
    out.push_str(&format!(
        "C {}\n",
        match test {
            ClipTest::Reject => 0,
            ClipTest::Accept => 1,
            ClipTest::Clip => 2,
        }
    ));
    match test {
        ClipTest::Reject => {}
        ClipTest::Accept => print_setup(&mut out, setup_triangle(&vp, c.pos, cull, front)),
        ClipTest::Clip => {
            let vertex = |i: usize| {
                let mut varyings = [0.0; MAX_VARYINGS];
                varyings[..NV].copy_from_slice(&c.varyings[i]);
                ClipVertex {
                    pos_clip: c.pos[i],
                    varyings,
                }
            };
            let mut poly = ClipPolygon::triangle(vertex(0), vertex(1), vertex(2));
            poly.clip(&guard, NV);
            let verts = poly.vertices();
            out.push_str(&format!("N {}\n", verts.len()));
            for v in verts {
                out.push('V');
                for x in v.pos_clip.to_array() {
                    out.push(' ');
                    out.push_str(&hex(x));
                }
                for x in &v.varyings[..NV] {
                    out.push(' ');
                    out.push_str(&hex(*x));
                }
                out.push('\n');
            }
            if verts.iter().any(|v| !v.pos_clip.is_finite()) {
                return out;
            }
            for k in 1..verts.len().saturating_sub(1) {
                let p = [verts[0].pos_clip, verts[k].pos_clip, verts[k + 1].pos_clip];
                print_setup(&mut out, setup_triangle(&vp, p, cull, front));
            }
        }
    }
    out
}

#[test]
fn kernel_setup_and_clipping_match_the_core_bit_for_bit() {
    let Some(harness) = build_harness() else {
        return;
    };
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let cases: Vec<Case> = (0..6000).map(|_| random_case(&mut rng)).collect();
    let input: String = cases.iter().map(input_line).collect();
    let mut child = Command::new(&harness)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("run the harness");
    let mut stdin = child.stdin.take().expect("stdin");
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let output = child.wait_with_output().expect("harness output");
    writer.join().expect("writer").expect("write input");
    assert!(output.status.success(), "the harness failed");
    let device = String::from_utf8(output.stdout).expect("utf-8");
    let expected: String = cases.iter().map(rust_output).collect();
    let (mut accepted, mut clipped, mut covered) = (0, 0, 0);
    for line in expected.lines() {
        accepted += (line == "C 1") as u32;
        clipped += (line == "C 2") as u32;
        covered += (line.starts_with("P ") && line.split(' ').nth(3) == Some("1")) as u32;
    }
    // The cases exercise every path.
    assert!(
        accepted > 1000 && clipped > 500 && covered > 1000,
        "{accepted} {clipped} {covered}"
    );
    if device != expected {
        let mut case = 0;
        for (d, e) in device.lines().zip(expected.lines()) {
            if e.starts_with("C ") {
                case += 1;
            }
            assert_eq!(
                d,
                e,
                "case {} differs:\n{}",
                case,
                input_line(&cases[case - 1])
            );
        }
        assert_eq!(device.lines().count(), expected.lines().count());
    }
}

/// Runs the harness on `input` and returns its output.
fn run_harness(harness: &PathBuf, input: String) -> String {
    let mut child = Command::new(harness)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("run the harness");
    let mut stdin = child.stdin.take().expect("stdin");
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let output = child.wait_with_output().expect("harness output");
    writer.join().expect("writer").expect("write input");
    assert!(output.status.success(), "the harness failed");
    String::from_utf8(output.stdout).expect("utf-8")
}

#[test]
fn kernel_matrices_and_vertex_transform_match_glam() {
    let Some(harness) = build_harness() else {
        return;
    };
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let mut input = String::new();
    let mut expected = String::new();
    for _ in 0..2000 {
        let mut r = || rng.range(-3.0, 3.0);
        let view = Mat4::look_at_rh(
            Vec3::new(r(), r(), r() + 8.0),
            Vec3::new(r(), r(), r()),
            Vec3::Y,
        );
        let projection =
            Mat4::perspective_rh_gl(0.2 + r().abs() * 0.4, 1.0 + r().abs(), 0.01, 100.0);
        let vp = projection * view;
        let model = Mat4::from_scale_rotation_translation(
            Vec3::new(r(), r(), r()),
            Quat::from_euler(glam::EulerRot::XYZ, r(), r(), r()),
            Vec3::new(r(), r(), r()),
        );
        let p = Vec3::new(r(), r(), r());
        input.push('M');
        for v in vp
            .to_cols_array()
            .iter()
            .chain(&model.to_cols_array())
            .chain(&p.to_array())
        {
            input.push(' ');
            input.push_str(&hex(*v));
        }
        input.push('\n');
        // As MaterialShader::new and ::vertex compute them.
        let mvp = vp * model;
        let clip = mvp * p.extend(1.0);
        expected.push('M');
        for v in mvp.to_cols_array().iter().chain(&clip.to_array()) {
            expected.push(' ');
            expected.push_str(&hex(*v));
        }
        expected.push('\n');
    }
    let device = run_harness(&harness, input);
    for (i, (d, e)) in device.lines().zip(expected.lines()).enumerate() {
        assert_eq!(d, e, "case {i}");
    }
    assert_eq!(device.lines().count(), 2000);
}

/// Texture sampling: the kernels filter linear `f32` texels decoded at upload from the core's
/// RGBA8 levels, the core's scalar sampler decodes as it fetches; the two may round the last
/// bit differently (bit identity is promised for coverage and depth, not for texture
/// filtering), so each channel must agree within 4e-6 — far below one 8-bit level (3.9e-3).
#[test]
fn kernel_texture_sampling_matches_the_core() {
    let Some(harness) = build_harness() else {
        return;
    };
    let mut rng = Rng(0x0ddb_a11c_afe5_eed5);
    let sizes = [(1, 1), (5, 3), (8, 8), (16, 4), (3, 7)];
    let wraps = [Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat];
    let mins = [
        MinFilter::Nearest,
        MinFilter::Linear,
        MinFilter::NearestMipmapNearest,
        MinFilter::LinearMipmapNearest,
        MinFilter::NearestMipmapLinear,
        MinFilter::LinearMipmapLinear,
    ];
    let mut input = String::new();
    let mut expected = String::new();
    let cases = 3000;
    for _ in 0..cases {
        let (w, h) = sizes[rng.below(sizes.len() as u64) as usize];
        let texels = (0..w * h)
            .map(|_| Vec4::new(rng.unit(), rng.unit(), rng.unit(), rng.unit()))
            .collect();
        let texture = Texture::from_rgba_f32(w, h, texels).expect("texture");
        let sampler = Sampler {
            wrap_s: wraps[rng.below(3) as usize],
            wrap_t: wraps[rng.below(3) as usize],
            mag_filter: if rng.below(2) == 0 {
                Filter::Nearest
            } else {
                Filter::Linear
            },
            min_filter: mins[rng.below(6) as usize],
        };
        let uv = Vec2::new(rng.range(-3.0, 3.0), rng.range(-3.0, 3.0));
        let lod = match rng.below(4) {
            0 => -rng.unit(),
            1 => rng.range(0.0, 1.0),
            _ => rng.range(0.0, 5.0),
        };
        input.push_str(&format!("X {}", texture.level_count()));
        for level in texture.levels() {
            input.push_str(&format!(" {} {}", level.width, level.height));
            // The linear f32 texels the GPU is given (the 8-bit levels decoded at upload).
            for y in 0..level.height {
                for x in 0..level.width {
                    for v in level.texel(x, y).to_array() {
                        input.push(' ');
                        input.push_str(&hex(v));
                    }
                }
            }
        }
        input.push_str(&format!(
            " {} {} {} {} {} {} {}\n",
            wrap_code(sampler.wrap_s),
            wrap_code(sampler.wrap_t),
            filter_code(sampler.mag_filter),
            min_filter_code(sampler.min_filter),
            hex(uv.x),
            hex(uv.y),
            hex(lod)
        ));
        let c = texture.sample_lod(&sampler, uv, lod);
        expected.push('X');
        for v in c.to_array() {
            expected.push(' ');
            expected.push_str(&hex(v));
        }
        expected.push('\n');
    }
    let device = run_harness(&harness, input);
    let values = |line: &str| -> Vec<f32> {
        line.split_whitespace()
            .skip(1)
            .map(|h| f32::from_bits(u32::from_str_radix(h, 16).expect("hex float")))
            .collect()
    };
    for (i, (d, e)) in device.lines().zip(expected.lines()).enumerate() {
        let (d, e) = (values(d), values(e));
        assert_eq!(d.len(), e.len(), "case {i}");
        for (a, b) in d.iter().zip(&e) {
            let close = a == b || (a.is_nan() && b.is_nan()) || (a - b).abs() <= 4e-6;
            assert!(close, "case {i}: kernel {d:?}, core {e:?}");
        }
    }
    assert_eq!(device.lines().count(), cases);
}
