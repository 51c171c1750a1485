//! The instruction sets the f64 kernels are compiled for (AVX-512, AVX2, plain x86-64 and other
//! targets), chosen once at run time: every kernel gives the same bits on each.

/// The instruction sets a build can use, best first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    Avx512,
    Avx2,
    Plain,
}

/// The best instruction set of this CPU (`PREBO_ISA=avx512|avx2|plain` caps it, for tests).
pub fn best_isa() -> Isa {
    let cap = std::env::var("PREBO_ISA").unwrap_or_default().to_ascii_lowercase();
    #[cfg(target_arch = "x86_64")]
    {
        if cap != "avx2" && cap != "plain" && std::arch::is_x86_feature_detected!("avx512f") {
            return Isa::Avx512;
        }
        if cap != "plain" && std::arch::is_x86_feature_detected!("avx2") {
            return Isa::Avx2;
        }
    }
    let _ = cap;
    Isa::Plain
}

/// Whether this CPU has `isa`.
pub fn isa_available(isa: Isa) -> bool {
    match isa {
        Isa::Plain => true,
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => std::arch::is_x86_feature_detected!("avx2"),
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => std::arch::is_x86_feature_detected!("avx512f"),
        #[cfg(not(target_arch = "x86_64"))]
        _ => false,
    }
}

/// `best_isa`, read once per process.
pub fn process_isa() -> Isa {
    static ISA: std::sync::OnceLock<Isa> = std::sync::OnceLock::new();
    *ISA.get_or_init(best_isa)
}
