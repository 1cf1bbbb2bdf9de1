//! A minimal binding to NVRTC, the CUDA run-time compiler, opened with `dlopen` at run time.
//!
//! NVRTC needs no GPU and no driver, so the kernels can be compiled (and checked) anywhere the
//! library exists: CI gets it from the `nvidia-cuda-nvrtc` Python wheel. The library is found
//! through `KANTELE_NVRTC` (a path to `libnvrtc.so.*` or to the folder holding it), then by the
//! usual names on the loader's search path. cudarc's own NVRTC binding is not used because it
//! can only search by name and panics when the library is missing; this one returns errors.
//!
//! All `unsafe` of this module is the FFI calls below, each with its `SAFETY:` argument.

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};

/// What went wrong while loading NVRTC or compiling a kernel.
#[derive(Debug, thiserror::Error)]
pub enum NvrtcError {
    /// The library could not be opened (or lacks a function).
    #[error("cannot load NVRTC ({0}); install the CUDA 13.0 NVRTC (e.g. pip nvidia-cuda-nvrtc==13.0.*) and set KANTELE_NVRTC to libnvrtc.so.13")]
    Load(String),
    /// A source failed to compile; the log says why.
    #[error("NVRTC failed to compile {name}: {log}")]
    Compile {
        /// The source's name.
        name: String,
        /// The compiler's log (first lines).
        log: String,
    },
    /// An NVRTC call returned an error code.
    #[error("NVRTC call {call} failed: {message}")]
    Call {
        /// The function.
        call: &'static str,
        /// NVRTC's description of the error.
        message: String,
    },
}

type Program = *mut c_void;
type VersionFn = unsafe extern "C" fn(*mut c_int, *mut c_int) -> c_int;
type CreateFn = unsafe extern "C" fn(
    *mut Program,
    *const c_char,
    *const c_char,
    c_int,
    *const *const c_char,
    *const *const c_char,
) -> c_int;
type CompileFn = unsafe extern "C" fn(Program, c_int, *const *const c_char) -> c_int;
type SizeFn = unsafe extern "C" fn(Program, *mut usize) -> c_int;
type GetFn = unsafe extern "C" fn(Program, *mut c_char) -> c_int;
type DestroyFn = unsafe extern "C" fn(*mut Program) -> c_int;
type ErrorStringFn = unsafe extern "C" fn(c_int) -> *const c_char;

/// An opened NVRTC library.
pub struct Nvrtc {
    version: VersionFn,
    create: CreateFn,
    compile: CompileFn,
    log_size: SizeFn,
    log: GetFn,
    ptx_size: SizeFn,
    ptx: GetFn,
    destroy: DestroyFn,
    error_string: ErrorStringFn,
    path: String,
    // Keeps the function pointers above valid; dropped last.
    _library: libloading::Library,
    // NVRTC's builtins library, opened first from the same folder (see `open`).
    _builtins: Option<libloading::Library>,
}

/// A header made available to `#include` while compiling.
#[derive(Clone, Copy, Debug)]
pub struct Header<'a> {
    /// The name used in `#include "name"`.
    pub name: &'a str,
    /// Its text.
    pub source: &'a str,
}

/// The result of a successful compilation.
#[derive(Clone, Debug)]
pub struct Compiled {
    /// PTX text (without the trailing NUL).
    pub ptx: String,
    /// The compiler's log (warnings); empty when clean.
    pub log: String,
}

impl Nvrtc {
    /// Where to look for the library: `KANTELE_NVRTC` first, then the usual names.
    pub fn candidates() -> Vec<PathBuf> {
        let mut out = Vec::new();
        if let Some(v) = std::env::var_os("KANTELE_NVRTC").filter(|v| !v.is_empty()) {
            let p = PathBuf::from(v);
            if p.is_dir() {
                for name in ["libnvrtc.so.13", "libnvrtc.so", "nvrtc64_130_0.dll"] {
                    out.push(p.join(name));
                }
            } else {
                out.push(p);
            }
            return out;
        }
        for name in ["libnvrtc.so.13", "libnvrtc.so", "nvrtc64_130_0.dll"] {
            out.push(PathBuf::from(name));
        }
        out
    }

    /// Opens the first library of [`Nvrtc::candidates`] that loads.
    pub fn load() -> Result<Self, NvrtcError> {
        let mut errors = Vec::new();
        for candidate in Self::candidates() {
            match Self::open(&candidate) {
                Ok(n) => return Ok(n),
                Err(e) => errors.push(e.to_string()),
            }
        }
        Err(NvrtcError::Load(errors.join("; ")))
    }

    /// Opens NVRTC from `path` (a file path, or a bare name for the loader's search path).
    pub fn open(path: &Path) -> Result<Self, NvrtcError> {
        let shown = path.display().to_string();
        // libnvrtc opens `libnvrtc-builtins.so.<version>` by name at compile time. The wheel's
        // copy sits beside it but is not on the loader's path, so open it first from there: the
        // loader then finds it already loaded by its soname.
        let builtins = path
            .parent()
            .filter(|dir| !dir.as_os_str().is_empty())
            .and_then(|dir| std::fs::read_dir(dir).ok())
            .and_then(|entries| {
                entries.flatten().map(|e| e.path()).find(|p| {
                    p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.starts_with("libnvrtc-builtins.so"))
                })
            })
            // SAFETY: as for NVRTC below: a plain C library with no initialiser preconditions.
            .and_then(|p| unsafe { libloading::Library::new(p) }.ok());
        // SAFETY: loading NVRTC runs its initialisers, which have no preconditions; the library
        // is a plain C library that does not unload itself.
        let library = unsafe { libloading::Library::new(path) }
            .map_err(|e| NvrtcError::Load(format!("{shown}: {e}")))?;
        macro_rules! sym {
            ($name:literal, $ty:ty) => {
                // SAFETY: the symbol is an NVRTC API function whose C signature is `$ty` (from
                // nvrtc.h, stable since CUDA 7); the pointer is copied out while `library`
                // stays alive in the returned struct.
                *unsafe { library.get::<$ty>($name) }
                    .map_err(|e| NvrtcError::Load(format!("{shown}: {e}")))?
            };
        }
        Ok(Self {
            version: sym!(b"nvrtcVersion\0", VersionFn),
            create: sym!(b"nvrtcCreateProgram\0", CreateFn),
            compile: sym!(b"nvrtcCompileProgram\0", CompileFn),
            log_size: sym!(b"nvrtcGetProgramLogSize\0", SizeFn),
            log: sym!(b"nvrtcGetProgramLog\0", GetFn),
            ptx_size: sym!(b"nvrtcGetPTXSize\0", SizeFn),
            ptx: sym!(b"nvrtcGetPTX\0", GetFn),
            destroy: sym!(b"nvrtcDestroyProgram\0", DestroyFn),
            error_string: sym!(b"nvrtcGetErrorString\0", ErrorStringFn),
            path: shown,
            _library: library,
            _builtins: builtins,
        })
    }

    /// The path or name the library was opened from.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// NVRTC's (major, minor) version, e.g. (13, 0).
    pub fn version(&self) -> Result<(i32, i32), NvrtcError> {
        let (mut major, mut minor) = (0, 0);
        // SAFETY: both pointers are valid for writes of one `int`.
        let code = unsafe { (self.version)(&mut major, &mut minor) };
        self.check("nvrtcVersion", code)?;
        Ok((major, minor))
    }

    fn check(&self, call: &'static str, code: c_int) -> Result<(), NvrtcError> {
        if code == 0 {
            return Ok(());
        }
        // SAFETY: nvrtcGetErrorString accepts any code and returns a static NUL-terminated
        // string (or NULL for unknown codes, handled below).
        let text = unsafe { (self.error_string)(code) };
        let message = if text.is_null() {
            format!("error {code}")
        } else {
            // SAFETY: non-null, NUL-terminated and static (see above).
            unsafe { CStr::from_ptr(text) }
                .to_string_lossy()
                .into_owned()
        };
        Err(NvrtcError::Call { call, message })
    }

    /// Compiles `source` (named `name` in messages) with `headers` and `options` to PTX.
    pub fn compile(
        &self,
        name: &str,
        source: &str,
        headers: &[Header<'_>],
        options: &[String],
    ) -> Result<Compiled, NvrtcError> {
        let nul = |s: &str| {
            CString::new(s).map_err(|_| NvrtcError::Call {
                call: "nvrtcCreateProgram",
                message: format!("{name}: text contains a NUL byte"),
            })
        };
        let c_source = nul(source)?;
        let c_name = nul(name)?;
        let header_sources = headers
            .iter()
            .map(|h| nul(h.source))
            .collect::<Result<Vec<_>, _>>()?;
        let header_names = headers
            .iter()
            .map(|h| nul(h.name))
            .collect::<Result<Vec<_>, _>>()?;
        let c_options = options
            .iter()
            .map(|o| nul(o))
            .collect::<Result<Vec<_>, _>>()?;
        let header_source_ptrs: Vec<*const c_char> =
            header_sources.iter().map(|s| s.as_ptr()).collect();
        let header_name_ptrs: Vec<*const c_char> =
            header_names.iter().map(|s| s.as_ptr()).collect();
        let option_ptrs: Vec<*const c_char> = c_options.iter().map(|s| s.as_ptr()).collect();

        let mut program: Program = std::ptr::null_mut();
        // SAFETY: every pointer is a live NUL-terminated string owned above (or an array of
        // them with the given length); NVRTC copies what it needs before returning.
        let code = unsafe {
            (self.create)(
                &mut program,
                c_source.as_ptr(),
                c_name.as_ptr(),
                headers.len() as c_int,
                header_source_ptrs.as_ptr(),
                header_name_ptrs.as_ptr(),
            )
        };
        self.check("nvrtcCreateProgram", code)?;
        let program = ProgramGuard {
            nvrtc: self,
            program,
        };
        // SAFETY: `program` was created above and is destroyed only by the guard; the options
        // array holds `option_ptrs.len()` live strings.
        let compiled = unsafe {
            (self.compile)(
                program.program,
                option_ptrs.len() as c_int,
                option_ptrs.as_ptr(),
            )
        };
        let log = self.read(program.program, self.log_size, self.log, "log")?;
        if compiled != 0 {
            return Err(NvrtcError::Compile {
                name: name.to_string(),
                log: log.trim().to_string(),
            });
        }
        let ptx = self.read(program.program, self.ptx_size, self.ptx, "PTX")?;
        Ok(Compiled {
            ptx,
            log: log.trim().to_string(),
        })
    }

    /// Reads a NUL-terminated text of `size(program)` bytes through `get`.
    fn read(
        &self,
        program: Program,
        size: SizeFn,
        get: GetFn,
        what: &'static str,
    ) -> Result<String, NvrtcError> {
        let mut len = 0usize;
        // SAFETY: `program` is live; `len` is valid for one write.
        self.check(what, unsafe { size(program, &mut len) })?;
        let mut buffer = vec![0u8; len.max(1)];
        // SAFETY: NVRTC writes exactly `len` bytes (the text and its NUL) into a buffer of at
        // least that size.
        self.check(what, unsafe { get(program, buffer.as_mut_ptr().cast()) })?;
        if let Some(end) = buffer.iter().position(|&b| b == 0) {
            buffer.truncate(end);
        }
        Ok(String::from_utf8_lossy(&buffer).into_owned())
    }
}

/// Destroys an NVRTC program when dropped.
struct ProgramGuard<'a> {
    nvrtc: &'a Nvrtc,
    program: Program,
}

impl Drop for ProgramGuard<'_> {
    fn drop(&mut self) {
        // SAFETY: `program` came from nvrtcCreateProgram and is destroyed exactly once, here.
        unsafe { (self.nvrtc.destroy)(&mut self.program) };
    }
}
