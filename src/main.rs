//! The `plyscape` binary: parse the command line, run, map errors to exit codes.

use clap::Parser;

fn main() {
    let cli = plyscape::cli::Cli::parse();
    if let Err(e) = plyscape::cli::execute(cli) {
        eprintln!("error: {e}");
        std::process::exit(e.exit_code());
    }
}
