//! The `plyscape` binary: parse the command line, run, map errors to exit codes.

use clap::Parser;

fn main() {
    // A closed pipe (`plyscape run | head`) ends the process quietly, as for
    // other Unix tools, instead of a panic inside println!.
    #[cfg(unix)]
    // SAFETY: called first thing in main, before any thread is spawned;
    // SIG_DFL is a valid disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = plyscape::cli::Cli::parse();
    if let Err(e) = plyscape::cli::execute(cli) {
        eprintln!("error: {e}");
        std::process::exit(e.exit_code());
    }
}
