use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    kapitza::signals::install();
    let mut out = std::io::stdout().lock();
    match kapitza::run(std::env::args_os(), &mut out) {
        Ok(()) => ExitCode::SUCCESS,
        // A reader that stops early (`| head`) is not a failure of the command.
        Err(kapitza::cli::Error::Run(e)) if broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = out.flush();
            e.report()
        }
    }
}

fn broken_pipe(e: &anyhow::Error) -> bool {
    let pipe = Some(std::io::ErrorKind::BrokenPipe);
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>().map(std::io::Error::kind) == pipe
            || c.downcast_ref::<serde_json::Error>()
                .and_then(serde_json::Error::io_error_kind)
                == pipe
    })
}
