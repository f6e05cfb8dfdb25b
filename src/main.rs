//! The `campaign` command line: parse, call the library, print. Nothing else lives here.
mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
