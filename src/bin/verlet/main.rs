//! The `verlet` command line (INTERFACE.md section 2): parses it, hands
//! each command to its module, and turns the outcome into an exit status.
//! The binary stands apart from the library, so that the library holds no
//! command line, no peer engine and no plotting.

use std::io::Write;
use std::process::ExitCode;

use verlet::Error;

/// `print!` that returns an error (`stdout_error`) instead of panicking
/// when stdout is closed or full; `main` ends quietly on a closed pipe.
macro_rules! out {
    ($($t:tt)*) => {
        std::io::Write::write_fmt(&mut std::io::stdout(), format_args!($($t)*)).map_err($crate::stdout_error)
    };
}

/// `println!` as [`out!`] is `print!`.
macro_rules! outln {
    ($($t:tt)*) => {
        out!("{}\n", format_args!($($t)*))
    };
}

/// `eprintln!` that never panics: std's panics when stderr cannot be
/// written (`2>/dev/full`), which would turn every error into exit 101 and
/// end a run at its first warning. What cannot be said on stderr is
/// dropped; the exit status still says how the command ended. (It shadows
/// std's for this crate's modules, all declared below it.)
macro_rules! eprintln {
    ($($t:tt)*) => {{
        let _ = std::io::Write::write_fmt(&mut std::io::stderr(), format_args!("{}\n", format_args!($($t)*)));
    }};
}

mod bench;
mod cli;
mod info;
mod lavapipe;
mod paths;
mod record;
mod run;
mod scene;

use cli::Command;

/// What a failed write to stdout becomes: an error naming stdout, or for
/// a reader that closed the pipe, the quiet end `main` gives it.
fn stdout_error(source: std::io::Error) -> Error {
    Error::Io { path: "stdout".into(), source }
}

/// Whether `e` is stdout's reader having gone (`verlet scene ... | head`).
fn is_closed_pipe(e: &Error) -> bool {
    matches!(e, Error::Io { path, source } if path == "stdout" && source.kind() == std::io::ErrorKind::BrokenPipe)
}

/// The exit status after stdout's reader went: 128 + SIGPIPE, as a shell
/// reports a tool that SIGPIPE ended (`yes | head`), so `set -o pipefail`
/// scripts see what they see of any other tool.
const CLOSED_PIPE_EXIT: u8 = 141;

fn main() -> ExitCode {
    // before any thread starts: it may set an environment variable
    verlet::gpu::quiet_window_system_probe();
    let cli = match cli::parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("{}", cli::clap_line(&e));
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        Command::Run(args) => run::run(args),
        Command::Scene { name, count, seed } => scene::print(&name, count, seed),
        Command::Info => info::info(),
        Command::Bench(args) => bench::command(args),
    };
    // what stdout still holds goes out now, so that a full disk is reported
    let result = result.and_then(|()| std::io::stdout().flush().map_err(stdout_error));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if is_closed_pipe(&e) => ExitCode::from(CLOSED_PIPE_EXIT),
        Err(e) => {
            eprintln!("error: {}", e.to_string().replace('\n', " "));
            ExitCode::FAILURE
        }
    }
}
