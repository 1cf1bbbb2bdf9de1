//! Output file names: templates with `{stem}`, `{index}` and `{frame}`. The writers themselves
//! are in [`kantele_output::output`] (shared with the Python package).

pub use kantele_output::output::write_png_rgba8;

use std::path::Path;

use anyhow::{anyhow, bail, Result};

/// Values that fill an output name template.
#[derive(Clone, Copy, Debug)]
pub struct TemplateVars<'a> {
    /// The scene's file stem or built-in name.
    pub stem: &'a str,
    /// The image's number among every image of the command.
    pub index: usize,
    /// The orbit view's number (0 without --orbit).
    pub frame: usize,
}

/// Digits a zero-padded number gets (at least 4, more when needed).
pub const MIN_DIGITS: usize = 4;

/// Whether the template has any placeholder.
pub fn has_placeholder(template: &str) -> bool {
    ["{stem}", "{index}", "{frame}"]
        .iter()
        .any(|p| template.contains(p))
}

/// Expands `{stem}`, `{index}` and `{frame}`; numbers are zero-padded to `digits`. Any other
/// `{...}` is an error.
pub fn expand_template(template: &str, vars: &TemplateVars, digits: usize) -> Result<String> {
    let mut out = String::with_capacity(template.len() + 16);
    let mut rest = template;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let after = &rest[open..];
        let close = after
            .find('}')
            .ok_or_else(|| anyhow!("{template}: unclosed '{{' in output template"))?;
        match &after[..=close] {
            "{stem}" => out.push_str(vars.stem),
            "{index}" => out.push_str(&format!("{:0digits$}", vars.index)),
            "{frame}" => out.push_str(&format!("{:0digits$}", vars.frame)),
            other => bail!(
                "{template}: unknown placeholder {other} in output template (use {{stem}}, {{index}} or {{frame}})"
            ),
        }
        rest = &after[close + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Digits for numbers below `count`.
pub fn digits_for(count: usize) -> usize {
    count
        .saturating_sub(1)
        .max(1)
        .to_string()
        .len()
        .max(MIN_DIGITS)
}

/// Lower-case extension of a path.
pub fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vars(stem: &str, index: usize, frame: usize) -> TemplateVars<'_> {
        TemplateVars { stem, index, frame }
    }

    #[test]
    fn template_expansion() {
        let v = vars("bunny", 7, 12);
        assert_eq!(
            expand_template("out/{stem}.png", &v, 4).unwrap(),
            "out/bunny.png"
        );
        assert_eq!(
            expand_template("{stem}-{index}-{frame}.png", &v, 4).unwrap(),
            "bunny-0007-0012.png"
        );
        assert_eq!(expand_template("plain.png", &v, 4).unwrap(), "plain.png");
        assert_eq!(
            expand_template("{frame}", &vars("x", 0, 123456), 4).unwrap(),
            "123456"
        );
        assert!(expand_template("{nope}.png", &v, 4).is_err());
        assert!(expand_template("{stem.png", &v, 4).is_err());
        assert!(has_placeholder("a/{index}.png"));
        assert!(!has_placeholder("a/index.png"));
    }

    #[test]
    fn digits() {
        assert_eq!(digits_for(0), 4);
        assert_eq!(digits_for(1), 4);
        assert_eq!(digits_for(10000), 4);
        assert_eq!(digits_for(10001), 5);
    }
}
