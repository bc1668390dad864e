//! `grainlaw`: see `grainlaw --help` and [`grainlaw::cli`].

fn main() {
    // A panic is a bug, but even then the user gets one line and exit code 2.
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        eprintln!(
            "error: internal error{at}: {}",
            msg.split_whitespace().collect::<Vec<_>>().join(" ")
        );
    }));
    let code = std::panic::catch_unwind(|| grainlaw::cli::main_with_args(std::env::args_os()))
        .unwrap_or(2);
    std::process::exit(code);
}
