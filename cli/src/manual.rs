//! `semo completions SHELL` and `semo man`: shell completion scripts and
//! manual pages, generated from the same clap definition that parses the
//! command line, so neither can describe an option `semo` does not have.

use std::io::Write;
use std::path::Path;

pub fn completions(
    mut command: clap::Command,
    shell: clap_complete::Shell,
    out: &mut impl Write,
) -> i32 {
    // Generated aside, then written: clap_complete panics on a write error
    // (`semo completions bash | head`).
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut command, "semo", &mut script);
    match out.write_all(&script).and_then(|()| out.flush()) {
        Ok(()) => 0,
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => 0,
        Err(e) => {
            eprintln!("error: cannot write the completion script: {e}");
            2
        }
    }
}

/// semo(1) on `out`, or every page (semo.1, semo-check.1, …) into `dir`.
pub fn man(command: clap::Command, dir: Option<&Path>, out: &mut impl Write) -> i32 {
    let written = match dir {
        None => clap_mangen::Man::new(command).render(out),
        Some(dir) => std::fs::create_dir_all(dir).and_then(|()| {
            clap_mangen::generate_to(command, dir)?;
            eprintln!("wrote the manual pages into {}", dir.display());
            Ok(())
        }),
    };
    match written {
        Ok(()) => 0,
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => 0,
        Err(e) => {
            eprintln!("error: cannot write the manual pages: {e}");
            2
        }
    }
}
