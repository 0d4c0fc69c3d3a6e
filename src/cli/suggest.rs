//! A mistyped subcommand: `termrast rastr` would otherwise open the viewer on a
//! model file `rastr` and fail with "No such file or directory", and `termrast rendr
//! --out x.png` with clap's complaint about `--out`.

use std::ffi::OsString;
use std::path::Path;

use clap::error::ErrorKind;
use clap::{CommandFactory, Parser};

use super::Cli;

/// Most edits (insertions, deletions, substitutions, swaps of neighbours) between a
/// word and a subcommand it is taken to be a typo of.
pub const MAX_EDITS: usize = 2;

/// The subcommands `word` is close to: those it is a prefix of, or else those within
/// [`MAX_EDITS`] edits, the closest first (several only when equally close).
#[must_use]
pub fn close_subcommands<'a>(word: &str, names: &[&'a str]) -> Vec<&'a str> {
    let word = word.to_lowercase();
    if word.is_empty() {
        return Vec::new();
    }
    let score = |name: &str| {
        if name.starts_with(&word) {
            0
        } else {
            edit_distance(&word, name)
        }
    };
    let best = names.iter().map(|n| score(n)).min().unwrap_or(usize::MAX);
    if best > MAX_EDITS {
        return Vec::new();
    }
    names.iter().copied().filter(|n| score(n) == best).collect()
}

/// Edit distance with adjacent transpositions (optimal string alignment), by chars.
#[must_use]
pub fn edit_distance(a: &str, b: &str) -> usize {
    strsim::osa_distance(a, b)
}

/// Whether `spec` names a built-in model rather than a file.
fn is_builtin_model(spec: &str) -> bool {
    matches!(spec, "teapot" | "bunny") || spec.starts_with("sphere:")
}

/// `a`, `a` or `b`, `a`, `b` or `c`, each in backticks.
fn either(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => quoted.concat(),
    }
}

/// What to say when the first argument of `args` (the whole command line, program
/// name first) is neither a subcommand, a built-in model nor an existing path, but is
/// close to a subcommand; `exists` says whether a path exists.
///
/// If the rest of the line is something the viewer takes, the word may have been
/// meant as a model file, and the message says both; otherwise it can only have been
/// meant as a subcommand.
#[must_use]
pub fn message(args: &[OsString], exists: impl Fn(&str) -> bool) -> Option<String> {
    let word = args.get(1)?.to_str()?;
    if word.starts_with('-') || is_builtin_model(word) || exists(word) {
        return None;
    }
    let cmd = Cli::command();
    let mut names: Vec<&str> = cmd.get_subcommands().map(clap::Command::get_name).collect();
    names.push("help");
    if names.contains(&word) {
        return None;
    }
    let close = close_subcommands(word, &names);
    if close.is_empty() {
        return None;
    }
    let viewer_takes_it = matches!(Cli::try_parse_from(args), Ok(Cli { command: None, .. }));
    Some(if viewer_takes_it {
        format!(
            "no file `{word}`; did you mean the subcommand {}?",
            either(&close)
        )
    } else {
        format!(
            "unrecognized subcommand `{word}`; did you mean {}?",
            either(&close)
        )
    })
}

/// The clap-style error (exit status 2) for a mistyped subcommand on this command
/// line, if it has one (see [`message`]).
#[must_use]
pub fn mistyped_subcommand(args: &[OsString]) -> Option<clap::Error> {
    let msg = message(args, |p| Path::new(p).exists())?;
    Some(Cli::command().error(ErrorKind::InvalidSubcommand, msg))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(words: &[&str]) -> Vec<OsString> {
        std::iter::once("termrast")
            .chain(words.iter().copied())
            .map(OsString::from)
            .collect()
    }

    #[test]
    fn distances() {
        assert_eq!(edit_distance("rastr", "raster"), 1);
        assert_eq!(edit_distance("bnech", "bench"), 1);
        assert_eq!(edit_distance("", "line"), 4);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("teapot", "render"), 5);
    }

    #[test]
    fn close_words() {
        let names = ["view", "raster", "line", "render", "bench", "help"];
        assert_eq!(close_subcommands("rastr", &names), ["raster"]);
        assert_eq!(close_subcommands("Rendr", &names), ["render"]);
        assert_eq!(close_subcommands("r", &names), ["raster", "render"]);
        assert_eq!(close_subcommands("lin", &names), ["line"]);
        assert!(close_subcommands("teapto", &names).is_empty());
        assert!(close_subcommands("model.obj", &names).is_empty());
    }

    #[test]
    fn messages() {
        let none = |_: &str| false;
        let m = message(&line(&["rastr"]), none).unwrap();
        assert_eq!(m, "no file `rastr`; did you mean the subcommand `raster`?");
        let m = message(&line(&["rendr", "--out", "x.png"]), none).unwrap();
        assert_eq!(m, "unrecognized subcommand `rendr`; did you mean `render`?");
        let m = message(&line(&["bnech", "render"]), none).unwrap();
        assert_eq!(m, "unrecognized subcommand `bnech`; did you mean `bench`?");
        // An existing file, a built-in model, a subcommand, an option: not a typo.
        assert_eq!(message(&line(&["rastr"]), |_| true), None);
        assert_eq!(message(&line(&["bunny"]), none), None);
        assert_eq!(message(&line(&["sphere:100"]), none), None);
        assert_eq!(message(&line(&["render"]), none), None);
        assert_eq!(message(&line(&["--fps", "10"]), none), None);
        assert_eq!(message(&line(&["missing.obj"]), none), None);
        assert_eq!(message(&line(&[]), none), None);
    }

    #[test]
    fn lists() {
        assert_eq!(either(&["a"]), "`a`");
        assert_eq!(either(&["a", "b"]), "`a` or `b`");
        assert_eq!(either(&["a", "b", "c"]), "`a`, `b` or `c`");
    }
}
