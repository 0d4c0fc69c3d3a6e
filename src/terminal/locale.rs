//! What the terminal's environment allows: Unicode glyphs (the locale's character set)
//! and a full-screen interface (not `TERM=dumb`).

/// The locale that decides the character set: the first of `LC_ALL`, `LC_CTYPE` and
/// `LANG` that is set and not empty (POSIX order); `None` is the C locale.
pub fn locale(get: impl Fn(&str) -> Option<String>) -> Option<String> {
    ["LC_ALL", "LC_CTYPE", "LANG"]
        .into_iter()
        .find_map(|k| get(k).filter(|v| !v.is_empty()))
}

/// Whether a locale's character set is UTF-8 (`en_GB.UTF-8`, `C.utf8`); the C and POSIX
/// locales are ASCII.
#[must_use]
pub fn is_utf8(locale: Option<&str>) -> bool {
    locale.is_some_and(|l| {
        let l = l.to_ascii_lowercase();
        l.contains("utf-8") || l.contains("utf8")
    })
}

/// Whether the terminal is one known to draw the Unicode 13 legacy computing wedges
/// itself (so no font can lack them): kitty, foot, Ghostty, WezTerm, Contour. `TERM`
/// survives SSH; `TERM_PROGRAM` is checked too, for local sessions.
pub fn draws_wedges(get: impl Fn(&str) -> Option<String>) -> bool {
    let term = get("TERM").unwrap_or_default();
    let program = get("TERM_PROGRAM").unwrap_or_default();
    [
        "xterm-kitty",
        "foot",
        "foot-extra",
        "xterm-ghostty",
        "wezterm",
        "contour",
    ]
    .contains(&term.as_str())
        || ["WezTerm", "ghostty", "contour"].contains(&program.as_str())
}

/// Why the viewer cannot draw a full-screen interface on this terminal, if it cannot.
#[must_use]
pub fn no_full_screen(term: Option<&str>) -> Option<String> {
    (term == Some("dumb")).then(|| {
        "TERM=dumb: this terminal cannot move the cursor, so the full-screen viewer cannot \
         run on it. Use `termrast render [MODEL] --cols 80 --rows 24` for text frames, \
         or `termrast render [MODEL] --out frame.png`"
            .to_string()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |k| {
            vars.iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| v.to_string())
        }
    }

    #[test]
    fn the_first_set_locale_variable_decides() {
        let cases: &[(&[(&str, &str)], bool)] = &[
            (&[("LANG", "en_US.UTF-8")], true),
            (&[("LANG", "C.utf8")], true),
            (&[("LANG", "C")], false),
            (&[("LC_ALL", "C"), ("LANG", "en_US.UTF-8")], false),
            (
                &[("LC_ALL", ""), ("LC_CTYPE", "de_DE.UTF-8"), ("LANG", "C")],
                true,
            ),
            (&[("LC_CTYPE", "POSIX"), ("LANG", "en_US.UTF-8")], false),
            (&[("LANG", "en_US.ISO-8859-1")], false),
            (&[], false),
        ];
        for (vars, want) in cases {
            assert_eq!(is_utf8(locale(env(vars)).as_deref()), *want, "{vars:?}");
        }
    }

    #[test]
    fn terminals_that_draw_wedges_are_recognised() {
        assert!(draws_wedges(env(&[("TERM", "xterm-kitty")])));
        assert!(draws_wedges(env(&[
            ("TERM", "xterm-256color"),
            ("TERM_PROGRAM", "WezTerm")
        ])));
        assert!(!draws_wedges(env(&[("TERM", "xterm-256color")])));
        assert!(!draws_wedges(env(&[])));
    }

    #[test]
    fn a_dumb_terminal_gets_no_full_screen_interface() {
        assert!(
            no_full_screen(Some("dumb"))
                .unwrap()
                .contains("termrast render")
        );
        assert_eq!(no_full_screen(Some("xterm-256color")), None);
        assert_eq!(no_full_screen(None), None);
    }
}
