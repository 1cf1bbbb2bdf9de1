//! Records how the binary was compiled, as `KANTELE_BUILD` ("opt-level 3", "opt-level 3,
//! profile-guided", ...), for `kantele --version` and the `build` field of `bench --json`:
//! benchmark figures name the build they came from (see `scripts/pgo-build.sh`).

fn main() {
    let opt_level = std::env::var("OPT_LEVEL").unwrap_or_else(|_| "?".into());
    // `RUSTFLAGS` as cargo hands it to rustc: the flags separated by 0x1f. `-Cprofile-use=…`
    // may also be written `-C profile-use=…`, which is two flags.
    let flags = std::env::var("CARGO_ENCODED_RUSTFLAGS").unwrap_or_default();
    let has = |option: &str| flags.split('\x1f').any(|f| f.contains(option));
    let pgo = if has("profile-use") {
        ", profile-guided"
    } else if has("profile-generate") {
        ", instrumented for profiling (slow)"
    } else {
        ""
    };
    let lean = if std::env::var_os("CARGO_FEATURE_LEAN_KERNELS").is_some() {
        ", lean kernels"
    } else {
        ""
    };
    println!("cargo:rustc-env=KANTELE_BUILD=opt-level {opt_level}{pgo}{lean}");
    println!("cargo:rerun-if-env-changed=CARGO_ENCODED_RUSTFLAGS");
    println!("cargo:rerun-if-changed=build.rs");
}
