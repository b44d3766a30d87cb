//! Writing to the terminal: a command's output, and text from outside made safe to print.

/// Write a command's output to stdout. A reader that stops early (`| head`) closes the pipe: the
/// rest is not wanted, so the program ends quietly, with the status a Unix tool killed by SIGPIPE
/// has (141), where `print!` would panic. Any other failure (a full disk, `> /dev/full`) loses the
/// output: one line says so and the program exits with 2, never 0 ("correct") over an answer
/// nobody got.
pub fn out(text: &str) {
    use std::io::Write;
    let mut stdout = std::io::stdout().lock();
    match stdout.write_all(text.as_bytes()).and_then(|_| stdout.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => std::process::exit(141),
        Err(e) => {
            eprintln!("error: cannot write to standard output: {e}");
            std::process::exit(2)
        }
        Ok(()) => {}
    }
}

/// `text` safe to print on a terminal: control characters (an escape sequence in a student's file
/// name would retitle the terminal or recolour the table, a newline break a row) and the
/// characters that reorder a line's display written as escapes (`\u{1b}`, `\n`). File names and
/// whatever else came from outside pass through this on their way to stdout or stderr.
pub fn printable(text: &str) -> String {
    let mut o = String::with_capacity(text.len());
    for c in text.chars() {
        let reorders = matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
        if c.is_control() || reorders {
            o.extend(c.escape_default());
        } else {
            o.push(c);
        }
    }
    o
}
