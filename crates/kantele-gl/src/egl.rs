//! Headless EGL: loads `libEGL.so.1` at run time, opens a display without any window system
//! (the device or the surfaceless platform), creates a desktop OpenGL 3.3+ core context and makes
//! it current on the calling thread without a surface.
//!
//! Everything here returns a message on failure instead of panicking, so that a machine without
//! EGL (or without a usable display) only makes [`crate::GlBackend::new`] fail.

use std::ffi::{c_char, c_void, CStr};
use std::sync::Mutex;

use khronos_egl as egl;

/// The EGL entry points, as loaded from `libEGL.so.1` (EGL 1.4 is enough: the platform
/// functions come from extensions).
pub(crate) type Egl = egl::DynamicInstance<egl::EGL1_4>;

/// `EGL_PLATFORM_DEVICE_EXT` (EGL_EXT_platform_device).
const PLATFORM_DEVICE_EXT: egl::Enum = 0x313F;
/// `EGL_PLATFORM_SURFACELESS_MESA` (EGL_MESA_platform_surfaceless).
const PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;
/// `EGL_DRM_DEVICE_FILE_EXT` (EGL_EXT_device_drm).
const DRM_DEVICE_FILE_EXT: egl::Int = 0x3233;

type GetPlatformDisplayExt =
    unsafe extern "system" fn(egl::Enum, *mut c_void, *const egl::Int) -> *mut c_void;
type QueryDevicesExt = unsafe extern "system" fn(egl::Int, *mut *mut c_void, *mut egl::Int) -> u32;
type QueryDeviceStringExt = unsafe extern "system" fn(*mut c_void, egl::Int) -> *const c_char;

/// How the display was opened.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Platform {
    /// `EGL_EXT_platform_device` with the given device (index, description).
    Device(usize, String),
    /// `EGL_MESA_platform_surfaceless`.
    Surfaceless,
    /// `eglGetDisplay(EGL_DEFAULT_DISPLAY)`.
    Default,
}

impl std::fmt::Display for Platform {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Platform::Device(i, what) => write!(f, "EGL device {i} ({what})"),
            Platform::Surfaceless => write!(f, "EGL surfaceless"),
            Platform::Default => write!(f, "EGL default display"),
        }
    }
}

/// Displays initialised by this process, with how many live contexts use each. An EGLDisplay
/// handle is shared by everyone who opens the same platform display, and `eglInitialize` does
/// not count, so the display is terminated only when its last user is gone (tests create several
/// backends at once on different threads).
static DISPLAY_USERS: Mutex<Vec<(usize, usize)>> = Mutex::new(Vec::new());

fn display_key(display: egl::Display) -> usize {
    display.as_ptr() as usize
}

/// Initialises `display` and counts one more user of it.
fn acquire_display(egl: &Egl, display: egl::Display) -> Result<(egl::Int, egl::Int), String> {
    let mut users = DISPLAY_USERS.lock().unwrap_or_else(|e| e.into_inner());
    let version = egl
        .initialize(display)
        .map_err(|e| format!("eglInitialize failed: {e}"))?;
    let key = display_key(display);
    match users.iter_mut().find(|(k, _)| *k == key) {
        Some((_, n)) => *n += 1,
        None => users.push((key, 1)),
    }
    Ok(version)
}

/// Drops one user of `display`, terminating it when that was the last one.
fn release_display(egl: &Egl, display: egl::Display) {
    let mut users = DISPLAY_USERS.lock().unwrap_or_else(|e| e.into_inner());
    let key = display_key(display);
    if let Some(pos) = users.iter().position(|(k, _)| *k == key) {
        users[pos].1 -= 1;
        if users[pos].1 == 0 {
            users.swap_remove(pos);
            // Nothing useful can be done about a failure while tearing down.
            let _ = egl.terminate(display);
        }
    }
}

/// A current, headless OpenGL context. Dropping it releases and destroys the context and
/// terminates the display when no other context of this process uses it.
pub(crate) struct EglContext {
    pub(crate) egl: Egl,
    display: egl::Display,
    context: egl::Context,
    /// How the display was opened.
    pub(crate) platform: Platform,
    /// EGL version of the display.
    pub(crate) version: (egl::Int, egl::Int),
}

impl EglContext {
    /// Loads EGL and creates a current context, trying the platforms in order (see
    /// [`crate::GlBackend::new`]). The error lists every attempt.
    pub(crate) fn new() -> Result<Self, String> {
        // SAFETY: libEGL.so.1 is the system's EGL library (glvnd or Mesa); loading it runs its
        // initialisers, which is what every EGL program does. (`Egl::load_required` would also
        // open the development link libEGL.so even when libEGL.so.1 loads.)
        let egl = unsafe { Egl::load_required_from_filename("libEGL.so.1") }
            .or_else(|first| {
                // SAFETY: as above.
                unsafe { Egl::load_required_from_filename("libEGL.so") }.map_err(|_| first)
            })
            .map_err(|e| format!("cannot load libEGL.so.1 (EGL 1.4): {e}"))?;
        let client_extensions = egl
            .query_string(None, egl::EXTENSIONS)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let has = |name: &str| client_extensions.split_whitespace().any(|e| e == name);

        let forced = std::env::var("KANTELE_GL_PLATFORM").ok();
        let mut attempts: Vec<String> = Vec::new();
        let mut candidates: Vec<Platform> = Vec::new();
        let devices = if has("EGL_EXT_platform_device") {
            query_devices(&egl).unwrap_or_else(|e| {
                attempts.push(format!("device enumeration: {e}"));
                Vec::new()
            })
        } else {
            Vec::new()
        };
        match forced.as_deref() {
            Some("surfaceless") => candidates.push(Platform::Surfaceless),
            Some("default") => candidates.push(Platform::Default),
            Some(s) if s == "device" || s.starts_with("device:") => {
                let index: usize = s
                    .strip_prefix("device:")
                    .map(|n| n.parse().unwrap_or(usize::MAX))
                    .unwrap_or(0);
                if let Some((_, what)) = devices.get(index) {
                    candidates.push(Platform::Device(index, what.clone()));
                } else {
                    attempts.push(format!(
                        "KANTELE_GL_PLATFORM={s}: no such device ({} found)",
                        devices.len()
                    ));
                }
            }
            Some(other) => {
                return Err(format!(
                    "KANTELE_GL_PLATFORM={other}: expected surfaceless, device, device:N or default"
                ))
            }
            None => {
                // A hardware device first (NVIDIA's EGL offers no surfaceless platform), then
                // Mesa's surfaceless platform (llvmpipe without a GPU), then a software device,
                // then whatever the default display is.
                for (i, (_, what)) in devices.iter().enumerate() {
                    if !what.contains("software") {
                        candidates.push(Platform::Device(i, what.clone()));
                    }
                }
                if has("EGL_MESA_platform_surfaceless") {
                    candidates.push(Platform::Surfaceless);
                }
                for (i, (_, what)) in devices.iter().enumerate() {
                    if what.contains("software") {
                        candidates.push(Platform::Device(i, what.clone()));
                    }
                }
                candidates.push(Platform::Default);
            }
        }

        for platform in candidates {
            match Self::create(&egl, &platform, &devices, has("EGL_EXT_platform_base")) {
                Ok((display, context, version)) => {
                    return Ok(Self {
                        egl,
                        display,
                        context,
                        platform,
                        version,
                    })
                }
                Err(e) => attempts.push(format!("{platform}: {e}")),
            }
        }
        Err(format!(
            "no usable EGL display for a desktop OpenGL 3.3 core context ({})",
            attempts.join("; ")
        ))
    }

    /// Opens one platform's display and creates a current context on it.
    fn create(
        egl: &Egl,
        platform: &Platform,
        devices: &[(*mut c_void, String)],
        platform_base: bool,
    ) -> Result<(egl::Display, egl::Context, (egl::Int, egl::Int)), String> {
        let display = match platform {
            Platform::Default => {
                // SAFETY: EGL_DEFAULT_DISPLAY is always a valid native display argument.
                unsafe { egl.get_display(egl::DEFAULT_DISPLAY) }
                    .ok_or_else(|| "eglGetDisplay returned no display".to_string())?
            }
            Platform::Surfaceless | Platform::Device(..) => {
                if !platform_base {
                    return Err("EGL_EXT_platform_base is missing".into());
                }
                let (kind, native) = match platform {
                    Platform::Device(i, _) => (PLATFORM_DEVICE_EXT, devices[*i].0),
                    _ => (PLATFORM_SURFACELESS_MESA, std::ptr::null_mut()),
                };
                let f = egl
                    .get_proc_address("eglGetPlatformDisplayEXT")
                    .ok_or("eglGetPlatformDisplayEXT not found")?;
                // SAFETY: the pointer is EGL's eglGetPlatformDisplayEXT, whose C signature is
                // `EGLDisplay (EGLenum, void *, const EGLint *)`.
                let get_platform_display: GetPlatformDisplayExt = unsafe { std::mem::transmute(f) };
                let attribs = [egl::NONE];
                // SAFETY: `native` is EGL_DEFAULT_DISPLAY (surfaceless) or an EGLDeviceEXT from
                // eglQueryDevicesEXT (device platform), as those extensions require; the
                // attribute list is terminated.
                let raw = unsafe { get_platform_display(kind, native, attribs.as_ptr()) };
                if raw.is_null() {
                    return Err(format!(
                        "eglGetPlatformDisplayEXT failed ({:?})",
                        egl.get_error()
                    ));
                }
                // SAFETY: `raw` is a display handle just returned by EGL.
                unsafe { egl::Display::from_ptr(raw) }
            }
        };
        let version = acquire_display(egl, display)?;
        let result = Self::create_context(egl, display);
        match result {
            Ok(context) => Ok((display, context, version)),
            Err(e) => {
                release_display(egl, display);
                Err(e)
            }
        }
    }

    fn create_context(egl: &Egl, display: egl::Display) -> Result<egl::Context, String> {
        let extensions = egl
            .query_string(Some(display), egl::EXTENSIONS)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let has = |name: &str| extensions.split_whitespace().any(|e| e == name);
        if !has("EGL_KHR_surfaceless_context") {
            return Err("EGL_KHR_surfaceless_context is missing".into());
        }
        egl.bind_api(egl::OPENGL_API)
            .map_err(|e| format!("eglBindAPI(EGL_OPENGL_API) failed: {e}"))?;
        let config = if has("EGL_KHR_no_config_context") {
            // SAFETY: EGL_NO_CONFIG_KHR (null) is a valid config with EGL_KHR_no_config_context.
            unsafe { egl::Config::from_ptr(std::ptr::null_mut()) }
        } else {
            let attribs = [egl::RENDERABLE_TYPE, egl::OPENGL_BIT, egl::NONE];
            egl.choose_first_config(display, &attribs)
                .map_err(|e| format!("eglChooseConfig failed: {e}"))?
                .ok_or("no EGL config supports desktop OpenGL")?
        };
        let attribs = [
            egl::CONTEXT_MAJOR_VERSION,
            3,
            egl::CONTEXT_MINOR_VERSION,
            3,
            egl::CONTEXT_OPENGL_PROFILE_MASK,
            egl::CONTEXT_OPENGL_CORE_PROFILE_BIT,
            egl::NONE,
        ];
        let context = egl
            .create_context(display, config, None, &attribs)
            .map_err(|e| format!("eglCreateContext (OpenGL 3.3 core) failed: {e}"))?;
        if let Err(e) = egl.make_current(display, None, None, Some(context)) {
            let _ = egl.destroy_context(display, context);
            return Err(format!("eglMakeCurrent without a surface failed: {e}"));
        }
        Ok(context)
    }

    /// Makes the context current on the calling thread unless it already is.
    pub(crate) fn make_current(&self) -> Result<(), String> {
        let current = self.egl.get_current_context();
        if current.map(|c| c.as_ptr()) == Some(self.context.as_ptr()) {
            return Ok(());
        }
        self.egl
            .make_current(self.display, None, None, Some(self.context))
            .map_err(|e| format!("eglMakeCurrent failed: {e}"))
    }

    /// Address of a GL function, null when EGL does not know it.
    pub(crate) fn proc_address(&self, name: &str) -> *const c_void {
        self.egl
            .get_proc_address(name)
            .map_or(std::ptr::null(), |f| f as *const c_void)
    }
}

impl Drop for EglContext {
    fn drop(&mut self) {
        // Failures while tearing down cannot be reported; the process keeps running.
        let _ = self.egl.make_current(self.display, None, None, None);
        let _ = self.egl.destroy_context(self.display, self.context);
        release_display(&self.egl, self.display);
    }
}

/// The EGL devices (handle, description), via EGL_EXT_device_enumeration.
fn query_devices(egl: &Egl) -> Result<Vec<(*mut c_void, String)>, String> {
    let query = egl
        .get_proc_address("eglQueryDevicesEXT")
        .ok_or("eglQueryDevicesEXT not found")?;
    // SAFETY: eglQueryDevicesEXT has the C signature
    // `EGLBoolean (EGLint max_devices, EGLDeviceEXT *devices, EGLint *num_devices)`.
    let query: QueryDevicesExt = unsafe { std::mem::transmute(query) };
    let describe: Option<QueryDeviceStringExt> = egl
        .get_proc_address("eglQueryDeviceStringEXT")
        // SAFETY: eglQueryDeviceStringEXT has the C signature
        // `const char *(EGLDeviceEXT device, EGLint name)`.
        .map(|f| unsafe { std::mem::transmute::<extern "system" fn(), QueryDeviceStringExt>(f) });
    let mut devices = vec![std::ptr::null_mut(); 16];
    let mut count: egl::Int = 0;
    // SAFETY: the array holds 16 device handles and `count` receives how many were written.
    let ok = unsafe { query(devices.len() as egl::Int, devices.as_mut_ptr(), &mut count) };
    if ok == 0 {
        return Err(format!("eglQueryDevicesEXT failed ({:?})", egl.get_error()));
    }
    devices.truncate(count.max(0) as usize);
    Ok(devices
        .into_iter()
        .map(|device| {
            let string = |name: egl::Int| -> Option<String> {
                let f = describe?;
                // SAFETY: `device` came from eglQueryDevicesEXT; the returned string is owned by
                // EGL and null when the query does not apply.
                let s = unsafe { f(device, name) };
                // SAFETY: a non-null result is a NUL-terminated string owned by EGL.
                (!s.is_null()).then(|| unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned())
            };
            let extensions = string(egl::EXTENSIONS).unwrap_or_default();
            let what = if extensions.contains("EGL_MESA_device_software") {
                "software".to_string()
            } else if let Some(file) = string(DRM_DEVICE_FILE_EXT) {
                file
            } else {
                "hardware".to_string()
            };
            (device, what)
        })
        .collect())
}
