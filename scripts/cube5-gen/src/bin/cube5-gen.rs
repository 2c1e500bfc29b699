//! `cube5-gen variants ...` and `cube5-gen regs ...`: the scripts' door to the `cube5_gen`
//! library (the same code `tb-rs/build.rs` uses).

use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("variants") => cube5_gen::variants::main(&args[1..]),
        Some("regs") => cube5_gen::regs::main(&args[1..]),
        Some("yosys") => cube5_gen::yosys::main(&args[1..]),
        _ => Err(
            "usage: cube5-gen variants|regs|yosys [...] (see scripts/cube5-gen/src/lib.rs)".into(),
        ),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("cube5-gen: {e}");
            ExitCode::FAILURE
        }
    }
}
