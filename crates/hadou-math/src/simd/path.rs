//! [`SimdPath`]: which lanes the running CPU can use, and the `HADOU_SIMD` override.

use std::sync::OnceLock;

/// The environment variable that picks a path by name (`portable`, `avx2`, `avx512`) instead of
/// the widest the CPU supports. A path the CPU lacks, or an unknown name, is refused.
pub const SIMD_ENV: &str = "HADOU_SIMD";

/// A vector path the running CPU supports: only [`SimdPath::supported`] and the functions built
/// on it make one, so running a [`super::dispatch`] body on it never meets an illegal
/// instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SimdPath(Kind);

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum Kind {
    Portable,
    #[cfg(target_arch = "x86_64")]
    Avx2,
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

/// Every path's name, narrowest first, on any machine.
const NAMES: [&str; 3] = ["portable", "avx2", "avx512"];

/// Why `HADOU_SIMD` (or a `--simd` flag) named no usable path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SimdPathError {
    /// Not one of the path names.
    Unknown(String),
    /// A path this CPU (or this build's architecture) cannot run.
    Unsupported {
        /// The path asked for.
        name: String,
        /// The paths this CPU runs.
        supported: Vec<&'static str>,
    },
}

impl std::fmt::Display for SimdPathError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Unknown(name) => {
                write!(f, "unknown vector path `{name}`: expected one of {}", NAMES.join(", "))
            }
            Self::Unsupported { name, supported } => write!(
                f,
                "this CPU cannot run the `{name}` vector path (it lacks the instructions); it runs: {}",
                supported.join(", ")
            ),
        }
    }
}

impl std::error::Error for SimdPathError {}

impl SimdPath {
    /// The lanes every build has ([`super::Portable`]).
    pub const PORTABLE: SimdPath = SimdPath(Kind::Portable);

    pub(super) fn kind(self) -> Kind {
        self.0
    }

    /// The path's name, as `HADOU_SIMD` and `--simd` take it.
    pub fn name(self) -> &'static str {
        match self.0 {
            Kind::Portable => "portable",
            #[cfg(target_arch = "x86_64")]
            Kind::Avx2 => "avx2",
            #[cfg(target_arch = "x86_64")]
            Kind::Avx512 => "avx512",
        }
    }

    /// What the path runs on, for tables and logs.
    pub fn describe(self) -> &'static str {
        match self.0 {
            Kind::Portable if cfg!(target_arch = "x86_64") => "8 lanes as two SSE2 halves",
            Kind::Portable if cfg!(target_arch = "aarch64") => "8 lanes as two NEON halves",
            Kind::Portable => "8 lanes, the build's vector width",
            #[cfg(target_arch = "x86_64")]
            Kind::Avx2 => "8 lanes in one AVX2 register, FMA",
            #[cfg(target_arch = "x86_64")]
            Kind::Avx512 => "8 lanes, AVX2 + FMA compiled with AVX-512VL's registers",
        }
    }

    /// Every path the running CPU supports, narrowest first (always [`SimdPath::PORTABLE`]).
    pub fn supported() -> Vec<SimdPath> {
        #[allow(unused_mut)]
        let mut paths = vec![SimdPath::PORTABLE];
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
                paths.push(SimdPath(Kind::Avx2));
                if std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512vl")
                {
                    paths.push(SimdPath(Kind::Avx512));
                }
            }
        }
        paths
    }

    /// The path hadou picks by itself: the widest the CPU supports.
    pub fn widest() -> SimdPath {
        *Self::supported().last().unwrap_or(&SimdPath::PORTABLE)
    }

    /// The path named `name` (`portable`, `avx2`, `avx512`), if this CPU runs it.
    pub fn from_name(name: &str) -> Result<SimdPath, SimdPathError> {
        let name = name.trim();
        if !NAMES.contains(&name) {
            return Err(SimdPathError::Unknown(name.to_string()));
        }
        let supported = Self::supported();
        supported.iter().copied().find(|p| p.name() == name).ok_or_else(|| SimdPathError::Unsupported {
            name: name.to_string(),
            supported: supported.iter().map(|p| p.name()).collect(),
        })
    }

    /// The path `HADOU_SIMD` names, or the widest where it is unset or empty.
    pub fn from_env() -> Result<SimdPath, SimdPathError> {
        match std::env::var(SIMD_ENV) {
            Ok(v) if !v.trim().is_empty() => Self::from_name(&v),
            _ => Ok(Self::widest()),
        }
    }

    /// The path renders use, decided once per process: [`SimdPath::from_env`], or where
    /// `HADOU_SIMD` names no usable path, the widest (with a warning on standard error; the CLI
    /// refuses such a value before it renders).
    pub fn current() -> SimdPath {
        static CURRENT: OnceLock<SimdPath> = OnceLock::new();
        *CURRENT.get_or_init(|| {
            Self::from_env().unwrap_or_else(|e| {
                let widest = Self::widest();
                eprintln!("warning: {SIMD_ENV}: {e}; using `{}`", widest.name());
                widest
            })
        })
    }
}

impl std::fmt::Display for SimdPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
