//! The Markdown pages answer with links that lead somewhere: every relative
//! link of every `.md` file of the repository names a file that exists, and
//! every `#anchor` a heading of its page (GitHub's slugs: lower case, letters,
//! digits, `-` and `_` kept, spaces to `-`, a repeated heading numbered).
//! The command-line reference is the one the binary writes, and every `dermis`
//! command in the guide's code blocks parses.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if path.is_dir() {
            if !name.starts_with('.') && name != "target" {
                markdown_files(&path, out);
            }
        } else if name.ends_with(".md") {
            out.push(path);
        }
    }
}

/// The page without its fenced code blocks.
fn prose(text: &str) -> Vec<&str> {
    let mut fenced = false;
    text.lines()
        .filter(|line| {
            if line.trim_start().starts_with("```") {
                fenced = !fenced;
                return false;
            }
            !fenced
        })
        .collect()
}

fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

fn anchors(page: &Path) -> BTreeSet<String> {
    let text = std::fs::read_to_string(page).unwrap();
    let mut seen = std::collections::BTreeMap::<String, usize>::new();
    let mut out = BTreeSet::new();
    for line in prose(&text) {
        let hashes = line.chars().take_while(|&c| c == '#').count();
        if (1..=6).contains(&hashes) && line[hashes..].starts_with(' ') {
            let s = slug(line[hashes..].trim().trim_end_matches('#'));
            let n = seen.entry(s.clone()).or_insert(0);
            out.insert(if *n == 0 {
                s.clone()
            } else {
                format!("{s}-{n}")
            });
            *n += 1;
        }
    }
    out
}

/// The targets of `[text](target)` links in a page's prose.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in prose(text) {
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            rest = &rest[i + 2..];
            let end = rest.find([')', ' ']).unwrap_or(rest.len());
            out.push(rest[..end].to_string());
            rest = &rest[end..];
        }
    }
    out
}

#[test]
fn every_relative_link_and_anchor_resolves() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut pages = Vec::new();
    markdown_files(root, &mut pages);
    assert!(pages.len() >= 10, "found only {} pages", pages.len());
    let mut broken = Vec::new();
    let mut checked = 0;
    for page in &pages {
        let text = std::fs::read_to_string(page).unwrap();
        for target in links(&text) {
            if target.contains(':') && !target.starts_with('#') {
                continue; // https:, mailto:
            }
            checked += 1;
            let (path, anchor) = target.split_once('#').unwrap_or((&target, ""));
            let file = if path.is_empty() {
                page.clone()
            } else {
                page.parent().unwrap().join(path)
            };
            let shown = page.strip_prefix(root).unwrap().display();
            if !file.exists() {
                broken.push(format!("{shown}: {target} (no such file)"));
            } else if !anchor.is_empty()
                && file.extension().is_some_and(|e| e == "md")
                && !anchors(&file).contains(anchor)
            {
                broken.push(format!("{shown}: {target} (no such heading)"));
            }
        }
    }
    println!("{checked} relative links in {} pages", pages.len());
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

fn dermis(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_dermis"))
        .args(args)
        .output()
        .expect("the dermis binary runs")
}

#[test]
fn the_cli_reference_is_the_generated_one() {
    let out = dermis(&["cli-reference"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let generated = String::from_utf8(out.stdout).unwrap();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/reference/cli.md");
    let committed = std::fs::read_to_string(&path).expect("docs/reference/cli.md exists");
    assert!(
        generated == committed,
        "docs/reference/cli.md is stale: cargo run --release -- cli-reference > docs/reference/cli.md"
    );
}

/// The `dermis …` and `cargo run --release -- …` command lines of a page's
/// fenced code blocks, as arguments after the binary: continuation lines
/// joined, leading `VAR=value` assignments dropped, cut at `|`, `>`, `&&`, `#`.
fn commands(text: &str) -> Vec<Vec<String>> {
    let mut fenced = false;
    let mut lines = Vec::new();
    let mut pending = String::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            continue;
        }
        pending.push_str(line.trim());
        if pending.ends_with('\\') {
            pending.pop();
            pending.push(' ');
        } else {
            lines.push(std::mem::take(&mut pending));
        }
    }
    let mut out = Vec::new();
    for line in lines {
        let mut words = split(&line).into_iter().peekable();
        while words
            .peek()
            .is_some_and(|w| w.contains('=') && !w.starts_with('-'))
        {
            words.next();
        }
        let words: Vec<String> = words
            .take_while(|w| !matches!(w.as_str(), "|" | ">" | ">>" | "&&" | "#"))
            .collect();
        let args = match words.iter().map(String::as_str).collect::<Vec<_>>()[..] {
            ["dermis", ..] => words[1..].to_vec(),
            ["cargo", "run", "--release", "--", ..] => words[4..].to_vec(),
            _ => continue,
        };
        out.push(args);
    }
    out
}

/// Words of a shell line, with '…' and "…" quoting.
fn split(line: &str) -> Vec<String> {
    let (mut words, mut word, mut quote) = (Vec::new(), String::new(), None);
    let mut started = false;
    for c in line.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => word.push(c),
            (None, '\'' | '"') => {
                quote = Some(c);
                started = true;
            }
            (None, c) if c.is_whitespace() => {
                if started || !word.is_empty() {
                    words.push(std::mem::take(&mut word));
                }
                started = false;
            }
            (None, c) => word.push(c),
        }
    }
    if started || !word.is_empty() {
        words.push(word);
    }
    words
}

fn parses(args: &[String]) -> Result<(), String> {
    let mut argv = vec!["cli-reference".to_string(), "--parses".to_string()];
    argv.extend(args.iter().cloned());
    let argv: Vec<&str> = argv.iter().map(String::as_str).collect();
    let out = dermis(&argv);
    match out.status.success() {
        true => Ok(()),
        false => Err(String::from_utf8_lossy(&out.stderr).into_owned()),
    }
}

#[test]
fn the_guides_commands_parse() {
    let guide = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/guide");
    let mut pages = Vec::new();
    markdown_files(&guide, &mut pages);
    assert!(pages.len() >= 5, "found only {} guide pages", pages.len());
    let mut wrong = Vec::new();
    let mut checked = 0;
    for page in &pages {
        for args in commands(&std::fs::read_to_string(page).unwrap()) {
            checked += 1;
            if let Err(e) = parses(&args) {
                let shown = page.file_name().unwrap().to_string_lossy();
                wrong.push(format!("{shown}: dermis {}\n  {e}", args.join(" ")));
            }
        }
    }
    assert!(
        checked >= 10,
        "found only {checked} commands in docs/guide/"
    );
    assert!(
        wrong.is_empty(),
        "commands that do not parse:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn a_wrong_flag_is_caught() {
    let text = "```sh\nLP_NUM_THREADS=4 dermis render --no-such-flag \\\n  --out a.png\n```\n\
                ```sh\ncargo run --release -- sweep --resolutions '1024 2048' > log\n```\n";
    let found = commands(text);
    assert_eq!(
        found,
        [
            vec!["render", "--no-such-flag", "--out", "a.png"],
            vec!["sweep", "--resolutions", "1024 2048"],
        ]
    );
    assert!(parses(&found[0]).is_err());
    assert!(parses(&["render".into(), "--frames".into(), "2".into()]).is_ok());
}
