//! Tests of the lane implementations: every operation of every supported instruction set
//! against the scalar reference, bit for bit, on special and random values; the scalar
//! reference against `std`; ISA selection and dispatch.

use proptest::prelude::*;

use super::*;

/// Float inputs that trip up implementations: signed zeros, infinities, NaNs with payloads
/// (quiet and signalling), denormals, rounding ties, the edges of the `i32` range.
fn special_f32() -> Vec<f32> {
    let mut values = vec![
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        -0.5,
        1.5,
        -1.5,
        2.5,
        -2.5,
        0.499_999_97,
        -0.499_999_97,
        0.7,
        -0.7,
        3.0,
        -3.75,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        -f32::NAN,
        f32::from_bits(0x7f80_0001), // signalling NaN
        f32::from_bits(0xffa0_0001), // negative signalling NaN
        f32::from_bits(0x7fc1_2345), // quiet NaN with a payload
        f32::from_bits(1),           // smallest denormal
        -f32::from_bits(0x0040_0000),
        f32::MIN_POSITIVE,
        f32::MAX,
        f32::MIN,
        8_388_607.5,
        8_388_608.0,
        -8_388_609.0,
        16_777_217.0,
        2_147_483_520.0, // largest f32 below 2^31
        2_147_483_648.0, // 2^31: out of the i32 range
        -2_147_483_648.0,
        -2_147_483_904.0,
        1e10,
        -1e-10,
    ];
    values.extend([0.25f32, 1e-38, 3.4e38].map(|v| -v));
    values
}

/// Integer inputs: the range edges, shift-sensitive patterns and small indices.
fn special_i32() -> Vec<i32> {
    vec![
        0,
        1,
        -1,
        2,
        -2,
        7,
        -8,
        31,
        36,
        37,
        100,
        i32::MIN,
        i32::MAX,
        i32::MIN + 1,
        i32::MAX - 1,
        16_777_217,
        -16_777_217,
        0x5555_5555,
        0x0f0f_f0f0,
        -0x1234_5678,
    ]
}

/// One batch of inputs for [`AllOps`].
#[derive(Clone, Debug)]
struct Inputs {
    a: [f32; 8],
    b: [f32; 8],
    ia: [i32; 8],
    ib: [i32; 8],
    bits_a: u8,
    bits_b: u8,
    table: Vec<u32>,
}

/// The result of every operation, named, as raw bits (`[u32; 8]` per operation; masks, scalars
/// and bytes in lane 0).
type Results = Vec<(&'static str, [u32; 8])>;

fn f32_bits(a: [f32; 8]) -> [u32; 8] {
    a.map(f32::to_bits)
}

fn i32_bits(a: [i32; 8]) -> [u32; 8] {
    a.map(|v| v as u32)
}

fn one(v: u32) -> [u32; 8] {
    [v, 0, 0, 0, 0, 0, 0, 0]
}

/// Runs every operation of the lane API on `Inputs`.
struct AllOps<'a>(&'a Inputs);

impl LaneKernel for AllOps<'_> {
    type Output = Results;

    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) -> Results {
        let i = self.0;
        let a = lanes.f32_from_array(i.a);
        let b = lanes.load_f32(&i.b);
        let ia = lanes.i32_from_array(i.ia);
        let ib = lanes.load_i32(&i.ib);
        let ma = lanes.mask_from_bits(i.bits_a);
        let mb = lanes.mask_from_bits(i.bits_b);
        let mut stored = [0.0f32; 9];
        a.store(&mut stored[1..]);
        let mut stored_masked = i.b;
        a.store_masked(ma, &mut stored_masked);
        let mut stored_i = [0i32; 8];
        ia.store(&mut stored_i);
        let mask = |m: L::Mask| one(u32::from(m.bits()));
        let flag = |v: bool| one(u32::from(v));
        vec![
            ("splat_f32", f32_bits(lanes.splat_f32(i.a[3]).to_array())),
            ("load_f32", f32_bits(b.to_array())),
            ("splat_i32", i32_bits(lanes.splat_i32(i.ia[5]).to_array())),
            ("load_i32", i32_bits(ib.to_array())),
            ("lane_index", i32_bits(lanes.lane_index().to_array())),
            ("mask_all(true)", mask(lanes.mask_all(true))),
            ("mask_all(false)", mask(lanes.mask_all(false))),
            ("add", f32_bits((a + b).to_array())),
            ("sub", f32_bits((a - b).to_array())),
            ("mul", f32_bits((a * b).to_array())),
            ("div", f32_bits((a / b).to_array())),
            ("mul_then_add", f32_bits((a * b + a).to_array())),
            ("neg", f32_bits((-a).to_array())),
            ("min", f32_bits(a.min(b).to_array())),
            ("max", f32_bits(a.max(b).to_array())),
            ("sqrt", f32_bits(a.sqrt().to_array())),
            ("abs", f32_bits(a.abs().to_array())),
            ("floor", f32_bits(a.floor().to_array())),
            ("round_ties_even", f32_bits(a.round_ties_even().to_array())),
            ("simd_lt", mask(a.simd_lt(b))),
            ("simd_le", mask(a.simd_le(b))),
            ("simd_gt", mask(a.simd_gt(b))),
            ("simd_ge", mask(a.simd_ge(b))),
            ("simd_eq", mask(a.simd_eq(b))),
            ("simd_ne", mask(a.simd_ne(b))),
            ("simd_eq(self)", mask(a.simd_eq(a))),
            ("store", f32_bits(stored[1..].try_into().unwrap())),
            ("store_masked", f32_bits(stored_masked)),
            ("to_i32_trunc", i32_bits(a.to_i32_trunc().to_array())),
            ("to_i32_floor", i32_bits(a.to_i32_floor().to_array())),
            ("to_bits", i32_bits(a.to_bits().to_array())),
            ("from_bits", f32_bits(L::F32::from_bits(ia).to_array())),
            ("extract(0)", one(a.extract(0).to_bits())),
            ("extract(6)", one(a.extract(6).to_bits())),
            ("permute", f32_bits(a.permute(ia).to_array())),
            (
                "permute(reverse)",
                f32_bits(
                    a.permute(lanes.i32_from_array([7, 6, 5, 4, 3, 2, 1, 0]))
                        .to_array(),
                ),
            ),
            ("reduce_min", one(a.reduce_min().to_bits())),
            ("reduce_max", one(a.reduce_max().to_bits())),
            ("i32 add", i32_bits((ia + ib).to_array())),
            ("i32 sub", i32_bits((ia - ib).to_array())),
            ("i32 mul", i32_bits((ia * ib).to_array())),
            ("i32 and", i32_bits((ia & ib).to_array())),
            ("i32 or", i32_bits((ia | ib).to_array())),
            ("i32 xor", i32_bits((ia ^ ib).to_array())),
            ("i32 not", i32_bits((!ia).to_array())),
            ("shl<0>", i32_bits(ia.shl::<0>().to_array())),
            ("shl<1>", i32_bits(ia.shl::<1>().to_array())),
            ("shl<13>", i32_bits(ia.shl::<13>().to_array())),
            ("shl<31>", i32_bits(ia.shl::<31>().to_array())),
            ("shr_arith<0>", i32_bits(ia.shr_arith::<0>().to_array())),
            ("shr_arith<1>", i32_bits(ia.shr_arith::<1>().to_array())),
            ("shr_arith<31>", i32_bits(ia.shr_arith::<31>().to_array())),
            ("shr_logical<0>", i32_bits(ia.shr_logical::<0>().to_array())),
            ("shr_logical<4>", i32_bits(ia.shr_logical::<4>().to_array())),
            (
                "shr_logical<31>",
                i32_bits(ia.shr_logical::<31>().to_array()),
            ),
            ("i32 min", i32_bits(ia.min(ib).to_array())),
            ("i32 max", i32_bits(ia.max(ib).to_array())),
            ("i32 simd_eq", mask(ia.simd_eq(ib))),
            ("i32 simd_eq(self)", mask(ia.simd_eq(ia))),
            ("i32 simd_gt", mask(ia.simd_gt(ib))),
            ("i32 simd_lt", mask(ia.simd_lt(ib))),
            ("to_f32", f32_bits(ia.to_f32().to_array())),
            ("i32 store", i32_bits(stored_i)),
            ("gather_u32", i32_bits(ia.gather_u32(&i.table).to_array())),
            (
                "gather_u32(ib)",
                i32_bits(ib.gather_u32(&i.table).to_array()),
            ),
            ("gather_u32(empty)", i32_bits(ia.gather_u32(&[]).to_array())),
            ("i32 extract(7)", one(ia.extract(7) as u32)),
            ("sign_bits", one(u32::from(ia.sign_bits()))),
            ("mask and", mask(ma.and(mb))),
            ("mask or", mask(ma.or(mb))),
            ("mask xor", mask(ma.xor(mb))),
            ("mask not", mask(ma.not())),
            ("mask and_not", mask(ma.and_not(mb))),
            ("mask any", flag(ma.any())),
            ("mask all", flag(ma.all())),
            ("mask none", flag(ma.none())),
            ("mask count", one(ma.count())),
            ("select_f32", f32_bits(ma.select_f32(a, b).to_array())),
            ("select_i32", i32_bits(mb.select_i32(ia, ib).to_array())),
            (
                "compare then select",
                f32_bits(a.simd_lt(b).select_f32(b, a).to_array()),
            ),
            ("isa", one(lanes.isa() as u32)),
        ]
    }
}

/// The instruction sets to compare with the scalar reference: every one this CPU supports.
fn supported_simd_isas() -> Vec<Isa> {
    Isa::ALL
        .into_iter()
        .filter(|&isa| isa != Isa::Scalar && isa.is_supported())
        .collect()
}

/// Operations that produce new NaNs by arithmetic: their NaN results may differ in payload and
/// sign (LLVM commutes `a + b`, as it may in any Rust float code); everything else is compared
/// bit for bit.
const NAN_PAYLOAD_UNSPECIFIED: &[&str] = &[
    "add",
    "sub",
    "mul",
    "div",
    "mul_then_add",
    "sqrt",
    "floor",
    "round_ties_even",
];

/// Equal bits, or both NaN.
fn same_or_both_nan(a: u32, b: u32) -> bool {
    a == b || (f32::from_bits(a).is_nan() && f32::from_bits(b).is_nan())
}

/// Asserts that every supported implementation gives the scalar reference's bits.
fn assert_same_as_scalar(inputs: &Inputs) {
    let reference = dispatch(Isa::Scalar, AllOps(inputs));
    for isa in supported_simd_isas() {
        let got = dispatch(isa, AllOps(inputs));
        assert_eq!(got.len(), reference.len());
        for ((name, want), (_, have)) in reference.iter().zip(&got) {
            if *name == "isa" {
                assert_eq!(
                    have[0],
                    isa.lanes() as u32,
                    "{isa} kernel ran another implementation"
                );
                continue;
            }
            let same = if NAN_PAYLOAD_UNSPECIFIED.contains(name) {
                have.iter().zip(want).all(|(&h, &w)| same_or_both_nan(h, w))
            } else {
                have == want
            };
            assert!(
                same,
                "{isa} `{name}` differs from scalar for {inputs:?}\n  {isa}: {have:x?}\nscalar: {want:x?}"
            );
        }
    }
}

fn gather_table() -> Vec<u32> {
    (0..37u32)
        .map(|k| k.wrapping_mul(0x9e37_79b9) ^ 0x8000_0001)
        .collect()
}

#[test]
fn every_isa_matches_scalar_on_all_pairs_of_special_values() {
    let floats = special_f32();
    let ints = special_i32();
    let pairs: Vec<(f32, f32)> = floats
        .iter()
        .flat_map(|&a| floats.iter().map(move |&b| (a, b)))
        .collect();
    for (chunk_index, chunk) in pairs.chunks(8).enumerate() {
        let lane = |k: usize| chunk[k % chunk.len()];
        let int = |k: usize| ints[(chunk_index * 3 + k) % ints.len()];
        let inputs = Inputs {
            a: std::array::from_fn(|k| lane(k).0),
            b: std::array::from_fn(|k| lane(k).1),
            ia: std::array::from_fn(int),
            ib: std::array::from_fn(|k| int(k + 11)),
            bits_a: (chunk_index as u8).wrapping_mul(37),
            bits_b: (chunk_index as u8).wrapping_mul(101) ^ 0x5a,
            table: gather_table(),
        };
        assert_same_as_scalar(&inputs);
    }
}

/// Floats from every bit pattern (NaNs, denormals, huge values) and from a range where
/// arithmetic and rounding are exercised.
fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        any::<u32>().prop_map(f32::from_bits),
        -1e4f32..1e4,
        (-64i32..64).prop_map(|k| k as f32 * 0.25),
        prop::sample::select(special_f32()),
    ]
}

fn any_i32() -> impl Strategy<Value = i32> {
    prop_oneof![
        any::<i32>(),
        -50i32..50,
        prop::sample::select(special_i32())
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn every_isa_matches_scalar_on_random_values(
        a in prop::array::uniform8(any_f32()),
        b in prop::array::uniform8(any_f32()),
        ia in prop::array::uniform8(any_i32()),
        ib in prop::array::uniform8(any_i32()),
        bits_a in any::<u8>(),
        bits_b in any::<u8>(),
        table in prop::collection::vec(any::<u32>(), 1..20),
    ) {
        assert_same_as_scalar(&Inputs { a, b, ia, ib, bits_a, bits_b, table });
    }

    #[test]
    fn scalar_helpers_match_std(bits in any::<u32>()) {
        let x = f32::from_bits(bits);
        // NaN payloads may differ (libm returns a signalling NaN unquieted, `roundss` quiets it).
        prop_assert!(same_or_both_nan(round_ties_even(x).to_bits(), x.round_ties_even().to_bits()));
        prop_assert!(same_or_both_nan(floor(x).to_bits(), x.floor().to_bits()));
    }
}

/// Runs the scalar implementation on `a` (and `b`).
fn scalar_f32(a: [f32; 8]) -> ScalarF32 {
    Scalar.f32_from_array(a)
}

#[test]
fn scalar_reference_follows_the_documented_semantics() {
    let s = Scalar;
    let x = scalar_f32([-0.0, 0.0, f32::NAN, 1.0, -2.5, 2.5, -0.4, 3e9]);
    let y = scalar_f32([0.0, -0.0, 1.0, f32::NAN, -2.5, 3.5, 0.4, 1.0]);
    // x86 minps/maxps: equal or NaN lanes give the second operand.
    let min = x.min(y).to_array();
    let max = x.max(y).to_array();
    assert_eq!(min[0].to_bits(), 0.0f32.to_bits());
    assert_eq!(min[1].to_bits(), (-0.0f32).to_bits());
    assert_eq!(min[2], 1.0);
    assert!(min[3].is_nan());
    assert_eq!(max[0].to_bits(), 0.0f32.to_bits());
    assert_eq!(max[2], 1.0);
    assert!(max[3].is_nan());
    // Rounding: ties to even, −0 kept, toward −∞.
    let round = x.round_ties_even().to_array();
    assert_eq!(round[4], -2.0);
    assert_eq!(round[5], 2.0);
    assert_eq!(round[6].to_bits(), (-0.0f32).to_bits());
    let floor = x.floor().to_array();
    assert_eq!(floor[0].to_bits(), (-0.0f32).to_bits());
    assert_eq!(floor[4], -3.0);
    assert_eq!(floor[6], -1.0);
    // cvttps2dq: NaN and out of range give i32::MIN.
    let trunc = x.to_i32_trunc().to_array();
    assert_eq!(trunc, [0, 0, i32::MIN, 1, -2, 2, 0, i32::MIN]);
    assert_eq!(x.to_i32_floor().to_array()[6], -1);
    // Comparisons: ordered, except `ne`.
    assert_eq!(x.simd_eq(y).bits(), 0b0001_0011);
    assert_eq!(x.simd_ne(y).bits(), 0b1110_1100);
    assert_eq!(x.simd_lt(y).bits(), 0b0110_0000);
    // Reductions in the documented tree order: min(min(min(a0,a4), min(a2,a6)), ...).
    let r = scalar_f32([f32::NAN, 5.0, 1.0, 2.0, 3.0, -0.0, 0.5, 0.0]);
    // (a0,a4) -> 3, (a1,a5) -> -0, (a2,a6) -> 0.5, (a3,a7) -> 0; then (3,0.5) -> 0.5,
    // (-0, 0) -> 0 (equal: the second); then (0.5, 0) -> 0.
    assert_eq!(r.reduce_min().to_bits(), 0.0f32.to_bits());
    // max: (3, 5, 1, 2), then (3, 5), then 5.
    assert_eq!(r.reduce_max(), 5.0);
    // Integers: wrapping, shifts, conversion, gather clamping.
    let i = s.i32_from_array([i32::MAX, -1, 5, -7, 0, 40, 16_777_217, i32::MIN]);
    assert_eq!((i + s.splat_i32(1)).to_array()[0], i32::MIN);
    assert_eq!(i.shr_arith::<1>().to_array()[3], -4);
    assert_eq!(i.shr_logical::<28>().to_array()[1], 15);
    assert_eq!(i.to_f32().to_array()[6], 16_777_216.0);
    assert_eq!(i.sign_bits(), 0b1000_1010);
    let table = [10, 20, 30];
    assert_eq!(
        i.gather_u32(&table).to_array(),
        [30, 10, 30, 10, 10, 30, 30, 10]
    );
    assert_eq!(i.gather_u32(&[]).to_array(), [0; 8]);
    // Masks.
    let m = s.mask_from_bits(0b1010_0110);
    assert_eq!(
        (m.count(), m.any(), m.all(), m.none()),
        (4, true, false, false)
    );
    assert_eq!(m.not().bits(), 0b0101_1001);
    assert_eq!(m.and_not(s.mask_from_bits(0b0000_0110)).bits(), 0b1010_0000);
    let mut out = [9.0f32; 8];
    s.splat_f32(1.0).store_masked(m, &mut out);
    assert_eq!(out, [9.0, 1.0, 1.0, 9.0, 9.0, 1.0, 9.0, 1.0]);
}

#[test]
fn short_slices_panic() {
    for isa in Isa::supported() {
        struct ShortLoad;
        impl LaneKernel for ShortLoad {
            type Output = ();
            fn run<L: Lanes>(self, lanes: L) {
                lanes.load_f32(&[1.0; 7]);
            }
        }
        let result = std::panic::catch_unwind(|| dispatch(isa, ShortLoad));
        assert!(result.is_err(), "{isa}: a 7-element load must panic");
    }
}

/// Reports which implementation a kernel ran with.
struct WhichIsa;

impl LaneKernel for WhichIsa {
    type Output = Isa;
    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) -> Isa {
        lanes.isa()
    }
}

#[test]
fn dispatch_runs_the_requested_isa_or_falls_back_to_scalar() {
    for isa in Isa::ALL {
        let ran = dispatch(isa, WhichIsa);
        if isa.is_supported() {
            assert_eq!(ran, isa.lanes());
        } else {
            assert_eq!(
                ran,
                Isa::Scalar,
                "unsupported {isa} must fall back to scalar"
            );
        }
    }
    assert_eq!(dispatch(Isa::Scalar, WhichIsa), Isa::Scalar);
}

#[cfg(target_arch = "x86_64")]
#[test]
fn avx2_dispatch_runs_avx2_code_where_the_cpu_has_it() {
    let has_avx2 = std::arch::is_x86_feature_detected!("avx2");
    let required = std::env::var("KANTELE_REQUIRE").unwrap_or_default();
    if required.split(',').any(|r| r.trim() == "avx2") {
        assert!(
            has_avx2,
            "KANTELE_REQUIRE names avx2, but this CPU lacks it"
        );
    }
    assert_eq!(Isa::Avx2.is_supported(), has_avx2);
    assert!(!Isa::Neon.is_supported());
    assert!(
        Isa::Sse2.is_supported(),
        "SSE2 is part of the x86-64 baseline"
    );
    assert_eq!(
        Isa::Sse41.is_supported(),
        std::arch::is_x86_feature_detected!("sse4.1")
    );
    let expected = if has_avx2 { Isa::Avx2 } else { Isa::Scalar };
    assert_eq!(dispatch(Isa::Avx2, WhichIsa), expected);
    let has_avx512 = has_avx2
        && std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl");
    assert_eq!(Isa::Avx512.is_supported(), has_avx512);
    // The AVX-512 level runs the AVX2 lanes.
    let expected = if has_avx512 { Isa::Avx2 } else { Isa::Scalar };
    assert_eq!(dispatch(Isa::Avx512, WhichIsa), expected);
    if has_avx512 {
        assert_eq!(Isa::best(), Isa::Avx512);
    } else if has_avx2 {
        assert_eq!(Isa::best(), Isa::Avx2);
    }
}

#[cfg(target_arch = "aarch64")]
#[test]
fn neon_dispatch_runs_neon_code() {
    assert!(Isa::Neon.is_supported(), "every AArch64 CPU has NEON");
    assert_eq!(dispatch(Isa::Neon, WhichIsa), Isa::Neon);
    assert_eq!(Isa::best(), Isa::Neon);
    for isa in [Isa::Sse2, Isa::Sse41, Isa::Avx2, Isa::Avx512] {
        assert!(!isa.is_supported());
        assert_eq!(dispatch(isa, WhichIsa), Isa::Scalar);
    }
}

#[test]
fn isa_names_round_trip() {
    for isa in Isa::ALL {
        assert_eq!(isa.name().parse::<Isa>(), Ok(isa));
        assert_eq!(isa.to_string(), isa.name());
        assert_eq!(isa.name().to_uppercase().parse::<Isa>(), Ok(isa));
    }
    assert_eq!("sse4.1".parse::<Isa>(), Ok(Isa::Sse41));
    let error = "avx10".parse::<Isa>().unwrap_err();
    assert!(error.contains("`avx10`") && error.contains("scalar, sse2, sse41, avx2, avx512, neon"));
}

#[test]
fn kantele_isa_values_parse_and_unsupported_ones_fall_back() {
    assert_eq!(parse_override(None), Ok(None));
    assert_eq!(parse_override(Some("")), Ok(None));
    assert_eq!(parse_override(Some("  ")), Ok(None));
    assert_eq!(parse_override(Some(" avx2 ")), Ok(Some(Isa::Avx2)));
    assert_eq!(parse_override(Some("Scalar")), Ok(Some(Isa::Scalar)));
    let error = parse_override(Some("mmx")).unwrap_err();
    assert!(
        error.starts_with("KANTELE_ISA: unknown instruction set `mmx`"),
        "{error}"
    );
    assert!(!error.contains('\n'));

    assert_eq!(choose(None), Isa::best());
    assert_eq!(choose(Some(Isa::Scalar)), Isa::Scalar);
    for isa in Isa::ALL {
        let expected = if isa.is_supported() { isa } else { Isa::best() };
        assert_eq!(choose(Some(isa)), expected);
    }
    assert!(Isa::best().is_supported());
    assert!(Isa::selected().is_supported());
    // `selected` honours a valid, supported KANTELE_ISA (as set in this process, if at all).
    if let Ok(Some(forced)) = Isa::from_env() {
        if forced.is_supported() {
            assert_eq!(Isa::selected(), forced);
        }
    }
}
