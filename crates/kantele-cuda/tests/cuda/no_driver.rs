//! Without a CUDA driver, the backend says so in one line and nothing panics; with one (on a GPU
//! machine) it starts. CI has no GPU, so there the first case is what is checked.

use kantele_cuda::{driver_present, CudaBackend};

#[test]
fn starting_without_a_driver_is_a_one_line_error() {
    match CudaBackend::new() {
        Ok(backend) => {
            assert!(driver_present(), "started without a driver library");
            eprintln!("CUDA device present: {}", backend.device());
        }
        Err(e) => {
            let message = e.to_string();
            eprintln!("{message}");
            assert!(!message.is_empty());
            assert!(!message.contains('\n'), "not one line: {message:?}");
            assert!(message.starts_with("cuda backend"), "{message}");
            if !driver_present() {
                assert!(message.contains("no CUDA driver"), "{message}");
            }
        }
    }
}

#[test]
fn a_missing_driver_is_reported_repeatably() {
    // Probing twice must give the same answer (no half-initialised global state).
    let first = CudaBackend::new().is_ok();
    let second = CudaBackend::new().is_ok();
    assert_eq!(first, second);
}
