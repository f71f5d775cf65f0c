//! Sets `cfg(marionette_data)` when `MARIONETTE_DATA` (the course data folder) is set at
//! build time: tests that need the data are marked ignored without it, so the runner
//! reports them as ignored rather than as passed. Sets `cfg(cpu_avx2)` and `cfg(cpu_avx512)`
//! when the building CPU runs those kernel levels, so the tests of a level it lacks are
//! reported as ignored, not passed. Also names the build profile for `bench`.

fn main() {
    // The build profile (`debug` for the dev profile, `release`), for `bench` to say how it
    // was measured.
    println!("cargo::rustc-env=MARIONETTE_BUILD_PROFILE={}", std::env::var("PROFILE").unwrap_or_default());
    println!("cargo::rerun-if-env-changed=MARIONETTE_DATA");
    println!("cargo::rustc-check-cfg=cfg(marionette_data)");
    if std::env::var_os("MARIONETTE_DATA").is_some() {
        println!("cargo::rustc-cfg=marionette_data");
    }
    println!("cargo::rustc-check-cfg=cfg(cpu_avx2, cpu_avx512)");
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        if has!("avx2") && has!("fma") {
            println!("cargo::rustc-cfg=cpu_avx2");
            if has!("avx512f") && has!("avx512vl") {
                println!("cargo::rustc-cfg=cpu_avx512");
            }
        }
    }
}
