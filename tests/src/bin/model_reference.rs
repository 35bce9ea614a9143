//! Prints the Rust model's response to a named reference input as CSV (see
//! `system_tests::reference`). Usage: `model-reference <case>`; `model-reference --list`.

use std::io::Write;
use system_tests::reference::CASES;

fn main() {
    let arg = std::env::args().nth(1);
    if arg.as_deref() == Some("--list") {
        for (name, desc, _) in CASES {
            println!("{name}: {desc}");
        }
        return;
    }
    let Some((_, _, run)) = CASES.iter().find(|c| Some(c.0) == arg.as_deref()) else {
        let names: Vec<&str> = CASES.iter().map(|c| c.0).collect();
        eprintln!(
            "model-reference: unknown case {arg:?}; cases: {}",
            names.join(", ")
        );
        std::process::exit(2);
    };
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    if let Err(e) = run(&mut out).and_then(|_| out.flush()) {
        eprintln!("model-reference: writing CSV: {e}");
        std::process::exit(1);
    }
}
