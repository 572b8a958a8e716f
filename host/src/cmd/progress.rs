//! Where a rig command's progress lines go.

use std::io::Write;

/// Progress goes with the answer on stdout, except under `--json`, whose stdout is one JSON
/// object a script parses: then it goes to stderr.
pub fn progress_writer(json: bool, out: &mut dyn Write) -> Box<dyn Write + '_> {
    if json {
        Box::new(std::io::stderr())
    } else {
        Box::new(out)
    }
}
