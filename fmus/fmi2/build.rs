// The FMI 2.0 logger callback is C-variadic. Stable Rust can call such a function pointer but
// cannot define one, so the importer side (the master, and the export layer's tests) installs this
// small C proxy as `fmi2CallbackFunctions.logger`; it formats the message and forwards it to a
// plain (non-variadic) Rust function. As a static archive member it is linked only where used,
// so the FMU shared libraries do not carry it.
fn main() {
    println!("cargo:rerun-if-changed=c/logger_proxy.c");
    cc::Build::new()
        .file("c/logger_proxy.c")
        .warnings(true)
        .compile("fmi2_logger_proxy");
}
