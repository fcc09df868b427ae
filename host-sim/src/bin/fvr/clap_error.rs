//! Command-line parser errors in the project's one-line form.

use std::process::ExitCode;

/// Print a parser error as one line, `fvr: error: …` (the message, clap's
/// tip and the usage line joined), with echoed values bounded in length
/// ([`fvr_host::text::bounded`]); `--help` and `--version` as clap prints
/// them.
pub(crate) fn exit(e: &clap::Error) -> ExitCode {
    let code = e.exit_code();
    if e.use_stderr() {
        eprintln!(
            "fvr: error: {}",
            fvr_host::text::bounded(&one_line(&e.render().to_string()))
        );
    } else {
        // Help and version text: printed whole (it is ours, not the user's).
        let _ = e.print();
    }
    ExitCode::from(u8::try_from(code).unwrap_or(2))
}

/// Clap's error text on one line: the message (with the indented lines
/// that continue it, such as the missing arguments), then each `tip:`, then
/// the usage, separated by `; `. The closing "For more information, try
/// '--help'." becomes "(see --help)".
fn one_line(text: &str) -> String {
    let mut message = Vec::new();
    let mut tips = Vec::new();
    let mut usage = None;
    let kept = |l: &&str| !l.is_empty() && !l.starts_with("For more information");
    for line in text.lines().map(str::trim).filter(kept) {
        if let Some(m) = line.strip_prefix("error: ") {
            message.push(m.trim_end_matches(':').to_string());
        } else if line.starts_with("tip: ") {
            tips.push(line.to_string());
        } else if let Some(u) = line.strip_prefix("Usage: ") {
            usage = Some(format!("usage: {u}"));
        } else if usage.is_none() && tips.is_empty() {
            message.push(line.to_string());
        }
    }
    // "…were not provided:" then one argument a line: "…: a, b".
    let head = match message.split_first() {
        Some((first, [])) => first.clone(),
        Some((first, rest)) => format!("{first}: {}", rest.join(", ")),
        None => "invalid arguments".to_string(),
    };
    let mut parts = vec![head];
    parts.extend(tips);
    parts.extend(usage);
    format!("{} (see --help)", parts.join("; "))
}

#[cfg(test)]
mod tests {
    use super::one_line;

    #[test]
    fn clap_errors_become_one_line() {
        let text = "error: the following required arguments were not provided:\n  \
                    --out <OUT>\n  <VOLUME>\n\nUsage: fvr render --out <OUT> <VOLUME>\n\nFor \
                    more information, try '--help'.\n";
        assert_eq!(
            one_line(text),
            "the following required arguments were not provided: --out <OUT>, <VOLUME>; \
             usage: fvr render --out <OUT> <VOLUME> (see --help)"
        );
        let text = "error: unexpected argument '--foo' found\n\n  tip: to pass '--foo' as a \
                    value, use '-- --foo'\n\nUsage: fvr render [OPTIONS]\n";
        assert_eq!(
            one_line(text),
            "unexpected argument '--foo' found; tip: to pass '--foo' as a value, use '-- \
             --foo'; usage: fvr render [OPTIONS] (see --help)"
        );
    }
}
