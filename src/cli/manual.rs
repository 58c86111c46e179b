//! `dermis cli-reference` (hidden): the command line's reference page,
//! docs/reference/cli.md, written from clap's command tree so that it cannot
//! fall behind the flags; and `--parses`, which says whether a command line
//! parses, for the docs test of the guide's commands.

use clap::{Arg, ArgAction, Args, Command};

#[derive(Args)]
pub struct ManualArgs {
    /// Parse the rest of the line as a dermis command line instead (exit 0 if
    /// it parses, else clap's error and 2); it is not run.
    #[arg(long, num_args = 1.., allow_hyphen_values = true, value_name = "ARGS")]
    parses: Option<Vec<String>>,
}

/// The page, or the parse of `--parses`: `command` is the binary's whole tree.
pub fn manual(args: ManualArgs, mut command: Command) -> dermis::Result<()> {
    match args.parses {
        Some(line) => {
            let argv = std::iter::once("dermis".to_string()).chain(line);
            if let Err(e) = command.try_get_matches_from_mut(argv) {
                let message = e.to_string();
                let message = message.trim_start_matches("error: ").trim_end();
                return Err(dermis::Error::Input(message.to_string()));
            }
        }
        None => out!("{}", markdown(&mut command)),
    }
    Ok(())
}

/// The reference page of `command` and its visible subcommands, depth first.
pub fn markdown(command: &mut Command) -> String {
    command.build();
    let mut page = String::from(
        "# Command-line reference\n\n\
         Written by `dermis cli-reference > docs/reference/cli.md` from the command \
         line's own definition; `cargo test --test it -- docs::` fails when it is stale. \
         `dermis <command> --help` prints the same.\n",
    );
    section(command, "dermis", &mut page);
    page
}

fn section(command: &Command, path: &str, page: &mut String) {
    page.push_str(&format!("\n## {path}\n\n"));
    if let Some(about) = command.get_long_about().or(command.get_about()) {
        page.push_str(&format!("{about}\n\n"));
    }
    let usage = command.clone().render_usage().to_string();
    let usage = usage.trim_start_matches("Usage: ");
    page.push_str(&format!("```text\n{usage}\n```\n\n"));
    let args: Vec<&Arg> = command
        .get_arguments()
        .filter(|a| !a.is_hide_set() && (path == "dermis" || !a.is_global_set()))
        .filter(|a| !matches!(a.get_action(), ArgAction::Help | ArgAction::Version))
        .collect();
    if !args.is_empty() {
        page.push_str("| option | what it does | default |\n|---|---|---|\n");
        for arg in args {
            page.push_str(&format!(
                "| {} | {} | {} |\n",
                name(arg),
                cell(&arg.get_help().map(|h| h.to_string()).unwrap_or_default()),
                defaults(arg)
            ));
        }
    }
    if path == "dermis" {
        page.push_str("\nThe options above apply to every command.\n");
    }
    for sub in command.get_subcommands().filter(|s| !s.is_hide_set()) {
        section(sub, &format!("{path} {}", sub.get_name()), page);
    }
}

/// `--flag VALUE`, `-v, --verbose`, or `FILE` for a positional.
fn name(arg: &Arg) -> String {
    let value = arg
        .get_value_names()
        .map(|v| v.join(" "))
        .unwrap_or_else(|| arg.get_id().as_str().to_uppercase());
    let takes_value = matches!(arg.get_action(), ArgAction::Set | ArgAction::Append);
    let mut flags: Vec<String> = Vec::new();
    if let Some(s) = arg.get_short() {
        flags.push(format!("-{s}"));
    }
    if let Some(l) = arg.get_long() {
        flags.push(format!("--{l}"));
    }
    let name = match (flags.is_empty(), takes_value) {
        (true, _) => value,
        (false, true) => format!("{} {value}", flags.join(", ")),
        (false, false) => flags.join(", "),
    };
    let env = arg
        .get_env()
        .map(|e| format!(" (env `{}`)", e.to_string_lossy()))
        .unwrap_or_default();
    format!("`{}`{env}", name.replace('|', "\\|"))
}

fn defaults(arg: &Arg) -> String {
    let values: Vec<String> = arg
        .get_default_values()
        .iter()
        .map(|v| v.to_string_lossy().into_owned())
        .collect();
    if values.is_empty() || matches!(arg.get_action(), ArgAction::SetTrue | ArgAction::Count) {
        String::new()
    } else {
        format!("`{}`", values.join(","))
    }
}

/// Text for one table cell: one line, pipes escaped.
fn cell(text: &str) -> String {
    text.split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .replace('|', "\\|")
}
