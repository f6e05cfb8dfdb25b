//! The `campaign` command line: everything is in the library's [`hinfix::cli`].

fn main() -> std::process::ExitCode {
    hinfix::cli::main()
}
