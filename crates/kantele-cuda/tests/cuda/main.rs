//! Tests of `kantele-cuda` that need no GPU: every kernel compiled with NVRTC, the kernels' set-up
//! code built as host C++ against the core, behaviour without a driver.
//!
//! One test binary with a module per subject: a binary per file would compile the shared
//! generic code and link every dependency into each (in a clean build, 31 test binaries took a
//! quarter of CI's compile time).

mod host_reference;
mod no_driver;
mod nvrtc_compile;
