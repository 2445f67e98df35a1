//! The documentation cannot drift from the code: `docs/cli.md`'s reference is the binary's own
//! `--help`, and every scenario fragment the README and `docs/` show passes `omniloop check`.

use crate::common::{bin, omniloop, tmp};
use std::path::{Path, PathBuf};

const BEGIN: &str = "<!-- generated from --help: begin -->";
const END: &str = "<!-- generated from --help: end -->";

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The commands `omniloop --help` lists, `help` left out.
fn commands(top_help: &str) -> Vec<String> {
    top_help
        .lines()
        .skip_while(|l| l.trim() != "Commands:")
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_owned)
        .collect()
}

/// The reference section: the top-level help, then each command's.
fn reference() -> String {
    let top = omniloop(["--help"]);
    let mut text = format!("{BEGIN}\n\n### `omniloop`\n\n```text\n{top}```\n");
    for command in commands(&top) {
        let help = omniloop([command.as_str(), "--help"]);
        text.push_str(&format!(
            "\n### `omniloop {command}`\n\n```text\n{help}```\n"
        ));
    }
    text.push('\n');
    text.push_str(END);
    text
}

#[test]
fn cli_reference_is_the_binarys_help() {
    let path = repo("docs/cli.md");
    let doc = std::fs::read_to_string(&path).unwrap();
    let (Some(b), Some(e)) = (doc.find(BEGIN), doc.find(END)) else {
        panic!("docs/cli.md lacks the markers {BEGIN} and {END}");
    };
    let generated = reference();
    assert!(
        generated.matches("### `omniloop ").count() >= 8,
        "{generated}"
    );
    let current = &doc[b..e + END.len()];
    if std::env::var_os("OMNILOOP_BLESS").is_some() {
        let updated = format!("{}{generated}{}", &doc[..b], &doc[e + END.len()..]);
        std::fs::write(&path, updated).unwrap();
        return;
    }
    assert!(
        current == generated,
        "docs/cli.md's reference differs from the binary's --help; write it anew with \
         `OMNILOOP_BLESS=1 cargo test --test suite docs::cli_reference`"
    );
}

/// The ```toml blocks of a Markdown text.
fn toml_blocks(text: &str) -> Vec<String> {
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        match (&mut current, line.trim_end()) {
            (None, "```toml") => current = Some(String::new()),
            (Some(block), "```") => {
                blocks.push(std::mem::take(block));
                current = None;
            }
            (Some(block), _) => {
                block.push_str(line);
                block.push('\n');
            }
            (None, _) => {}
        }
    }
    blocks
}

/// A block as a scenario. A block whose first line is `# in scenarios/NAME.toml` is a table of
/// that scenario: it is merged into it, its keys replacing the scenario's. Another fragment
/// gets the one key every one-robot scenario must have, `robot.start`. A block that is not TOML
/// is checked as written, so that the check names its line and column.
fn completed(block: &str) -> String {
    let Ok(table) = block.parse::<toml::Table>() else {
        return block.to_owned();
    };
    let base = block
        .lines()
        .next()
        .and_then(|l| l.strip_prefix("# in "))
        .map(|file| std::fs::read_to_string(repo(file.trim())).unwrap());
    let mut scenario: toml::Table = match base {
        Some(text) => text.parse().unwrap(),
        None if table.contains_key("robots") => return block.to_owned(),
        None => "[robot]\nstart = { x_mm = 0.0, y_mm = 0.0 }"
            .parse()
            .unwrap(),
    };
    merge(&mut scenario, table);
    toml::to_string(&scenario).unwrap()
}

/// Puts `over`'s keys into `base`, table into table.
fn merge(base: &mut toml::Table, over: toml::Table) {
    for (key, value) in over {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

#[test]
fn every_toml_block_in_the_docs_passes_check() {
    // The blocks are saved beside a copy of scenarios/cameras/, so that a camera file's
    // relative path resolves as it does for a reader who saves the block in scenarios/.
    let dir = tmp("docs_toml_blocks");
    std::fs::create_dir_all(dir.join("cameras")).unwrap();
    for e in std::fs::read_dir(repo("scenarios/cameras")).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), dir.join("cameras").join(e.file_name())).unwrap();
    }
    let mut pages: Vec<PathBuf> = std::fs::read_dir(repo("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    pages.push(repo("README.md"));
    pages.sort();
    let mut checked = 0;
    for page in &pages {
        let name = page.file_stem().unwrap().to_string_lossy().into_owned();
        for (i, block) in toml_blocks(&std::fs::read_to_string(page).unwrap())
            .iter()
            .enumerate()
        {
            let file = dir.join(format!("{name}_{i}.toml"));
            std::fs::write(&file, completed(block)).unwrap();
            let out = bin().arg("check").arg(&file).output().unwrap();
            assert!(
                out.status.success(),
                "{} block {i} fails omniloop check:\n{}\n{block}",
                page.display(),
                String::from_utf8_lossy(&out.stderr)
            );
            checked += 1;
        }
    }
    assert!(checked >= 4, "only {checked} TOML blocks found in docs/");
}
