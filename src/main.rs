//! The `slidebase` command line: parses arguments and dispatches; no physics here.

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    quiet_mesa_device_select_without_a_session();
    match cli::main() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line, no backtrace: these are user errors (bad flags, bad files) or a
            // solver that reports why it stopped. Causes already spelled out by the error
            // above them (an I/O error names its source) are not repeated.
            let mut message = e.to_string();
            for cause in e.chain().skip(1) {
                let cause = cause.to_string();
                if !message.contains(&cause) {
                    message.push_str(": ");
                    message.push_str(&cause);
                }
            }
            eprintln!("error: {}", shorten_long_words(&message));
            ExitCode::FAILURE
        }
    }
}

/// Mesa's Vulkan device-select layer (an implicit layer of every Vulkan instance where
/// Mesa's drivers are installed) asks Wayland for the session's default GPU, and
/// libwayland prints "error: XDG_RUNTIME_DIR is invalid or not set in the environment."
/// when there is no session: twice for each `render`, four times as the window opens, on
/// every headless machine (containers, CI) although nothing failed. Without
/// `XDG_RUNTIME_DIR` there is no Wayland session to ask, so the layer is switched off by
/// Mesa's own switch, `NODEVICE_SELECT` (it only orders the GPUs; wgpu chooses the adapter
/// itself). A user's own `NODEVICE_SELECT` is left as it is.
#[allow(unsafe_code)]
fn quiet_mesa_device_select_without_a_session() {
    if cfg!(target_os = "linux")
        && std::env::var_os("XDG_RUNTIME_DIR").is_none()
        && std::env::var_os("NODEVICE_SELECT").is_none()
    {
        // SAFETY: called first in `main`, before any thread exists that could read or
        // write the environment at the same time.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}

/// The longest word an error message echoes whole, in characters.
const MAX_ECHOED_CHARS: usize = 120;

/// `message` with every word (run of non-blank characters) longer than
/// [`MAX_ECHOED_CHARS`] cut to its start and end around its length: an error that quotes
/// a 10 MB `--scene` value, or a 300-digit number, stays a line a person can read.
fn shorten_long_words(message: &str) -> String {
    let mut shortened = String::with_capacity(message.len().min(4096));
    let mut rest = message;
    while !rest.is_empty() {
        let word_len = rest.find(char::is_whitespace).unwrap_or(rest.len());
        let (word, after) = rest.split_at(word_len);
        shortened.push_str(&shorten_word(word));
        let blank_len = after
            .find(|c: char| !c.is_whitespace())
            .unwrap_or(after.len());
        shortened.push_str(&after[..blank_len]);
        rest = &after[blank_len..];
    }
    shortened
}

/// One word cut as [`shorten_long_words`] says (whole if short enough).
fn shorten_word(word: &str) -> String {
    let count = word.chars().count();
    if count <= MAX_ECHOED_CHARS {
        return word.to_string();
    }
    let head: String = word.chars().take(60).collect();
    let tail: String = word.chars().skip(count - 20).collect();
    format!("{head}…[{count} characters]…{tail}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A long word is cut to 60 + 20 characters around its length; short ones, blanks and
    /// multi-byte characters are kept as they are.
    #[test]
    fn long_words_are_cut_and_the_rest_kept() {
        let long = "é".repeat(1000);
        let cut = shorten_long_words(&format!("bad  '{long}': give  Δt"));
        assert_eq!(
            cut,
            format!(
                "bad  '{}…[1003 characters]…{} give  Δt",
                "é".repeat(59),
                "é".repeat(18) + "':"
            )
        );
        assert_eq!(shorten_long_words("a b\nc"), "a b\nc");
    }
}
