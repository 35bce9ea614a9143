//! The fixture FMU loaded from its shared library, as an importer loads an FMU: a panic in
//! `fmi2GetReal` or `fmi2DoStep` is an fmi2Error whose message reaches the importer's logger, and nothing is
//! printed on the host's stderr (issue 19). Before, only calls other than the getters and
//! setters kept panics off stderr: the FMU library's own panic hook printed "thread ...
//! panicked at ..." for a getter.
//!
//! The check runs in a child process (this test binary again, with `PANIC_PROBE_CHILD` set) so
//! that its stderr can be read whole.

use fmi2_export::fmi2::{self, fmi2Error, fmi2OK, Fmi2Functions};
use fmi2_export::testing::Harness;
use panic_probe_fmu::PanicProbe;
use std::path::PathBuf;
use std::process::Command;

/// The fixture's shared library, built by cargo beside this test's binary.
fn library() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    let name = "libpanic_probe_fmu.so";
    [deps.join(name), deps.parent().unwrap().join(name)]
        .into_iter()
        .find(|p| p.is_file())
        .unwrap_or_else(|| panic!("{name} not found beside {}", exe.display()))
}

/// `table(lib)`: the FMI function table of a loaded library, one symbol per function.
macro_rules! table_from_library {
    (; $($name:ident $ty:ident $impl:ident ($($arg:ident : $argty:ty),*) -> $ret:ty;)*) => {
        fn table(lib: &libloading::Library) -> Fmi2Functions {
            Fmi2Functions {
                $($name: *unsafe {
                    lib.get::<fmi2::$ty>(concat!(stringify!($name), "\0").as_bytes())
                }
                .expect(stringify!($name)),)*
            }
        }
    };
}
fmi2::fmi2_functions!(table_from_library);

fn child() {
    let lib = unsafe { libloading::Library::new(library()) }.unwrap();
    let mut fmu = Harness::<PanicProbe>::instantiate(table(&lib), "probe");
    fmu.initialize(0.0);
    fmu.set("u", 2.0);
    assert_eq!(fmu.try_get::<f64>("y"), (fmi2OK, 2.0));
    fmu.set("u", 13.0);
    assert_eq!(fmu.try_get::<f64>("y").0, fmi2Error);
    let line = fmu.log().last();
    assert!(
        line.starts_with(
            "fmi2GetReal: internal error (panic: planted panic in a getter: u = 13) at \
             fmus/panic_probe/src/lib.rs:"
        ),
        "{line}"
    );
    // A second instance (the first is in the Error state): a panic in fmi2DoStep.
    let mut fmu = Harness::<PanicProbe>::instantiate(table(&lib), "probe2");
    fmu.initialize(0.0);
    fmu.set("u", 14.0);
    assert_eq!(fmu.try_step(0.0, 0.1), fmi2Error);
    let line = fmu.log().last();
    assert!(
        line.starts_with(
            "fmi2DoStep: internal error (panic: planted panic in a step: u = 14) at \
             fmus/panic_probe/src/lib.rs:"
        ),
        "{line}"
    );
    drop(fmu);
    println!("child done");
}

#[test]
fn panics_in_an_fmu_binary_go_to_the_logger_only() {
    if std::env::var_os("PANIC_PROBE_CHILD").is_some() {
        return child();
    }
    let out = Command::new(std::env::current_exe().unwrap())
        .args([
            "panics_in_an_fmu_binary_go_to_the_logger_only",
            "--exact",
            "--nocapture",
            "--test-threads=1",
        ])
        .env("PANIC_PROBE_CHILD", "1")
        .env_remove("RUST_BACKTRACE")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && stdout.contains("child done"),
        "child failed:\n{stdout}\n{stderr}"
    );
    assert!(
        !stderr.contains("panicked") && !stderr.contains("planted panic"),
        "the FMU printed on the host's stderr:\n{stderr}"
    );
}
