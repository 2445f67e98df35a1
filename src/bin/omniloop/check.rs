//! `omniloop check`: validate scenario files.

use super::Exit;
use omniloop::load_scenario;
use std::path::PathBuf;

/// `omniloop check`'s arguments.
#[derive(clap::Args)]
pub struct CheckArgs {
    /// Scenario files.
    #[arg(required = true)]
    files: Vec<PathBuf>,
}

/// `omniloop check`: every file loaded and checked, each problem printed; exits 2 when one
/// has any.
pub fn check_cmd(args: CheckArgs) -> anyhow::Result<()> {
    let mut bad = false;
    for f in &args.files {
        match load_scenario(f) {
            Ok(s) => println!("{}: ok ({})", f.display(), s.name),
            Err(e) => {
                eprintln!("{e}");
                bad = true;
            }
        }
    }
    if bad {
        return Err(Exit(2).into());
    }
    Ok(())
}
