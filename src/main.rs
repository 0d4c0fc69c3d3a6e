fn main() -> std::process::ExitCode {
    termrast::cli::main()
}
