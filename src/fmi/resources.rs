//! resources — turning fmi2Instantiate's `fmuResourceLocation` into a folder.
//!
//! Accepted forms: `file:///abs/path`, `file:/abs/path`, `file://localhost/abs/path`,
//! `file://HOST/...` is refused (not local), percent-encoding (`%20` …) anywhere in
//! a URI, and a plain absolute or relative path (some masters pass one).
//! Must never: panic on any input, or guess a path from a non-`file` URI.

use std::path::PathBuf;

/// The local folder named by a resource location, or why it names none.
pub fn resource_dir(location: &str) -> Result<PathBuf, String> {
    let loc = location.trim();
    if loc.is_empty() {
        return Err("empty fmuResourceLocation".into());
    }
    let lower = loc.get(..5).map(|s| s.to_ascii_lowercase());
    if lower.as_deref() != Some("file:") {
        // A scheme other than file: is not something we can open.
        if let Some((scheme, _)) = loc.split_once("://") {
            if !scheme.is_empty()
                && scheme
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
            {
                return Err(format!(
                    "fmuResourceLocation \"{loc}\" is not a file: URI or a path"
                ));
            }
        }
        return Ok(PathBuf::from(loc));
    }
    let rest = &loc[5..];
    let path = if let Some(after) = rest.strip_prefix("//") {
        // file://host/path: only an empty host or localhost is local.
        let (host, path) = match after.find('/') {
            Some(i) => (&after[..i], &after[i..]),
            None => (after, ""),
        };
        if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
            return Err(format!(
                "fmuResourceLocation \"{loc}\" names a remote host \"{host}\""
            ));
        }
        path
    } else {
        rest
    };
    if path.is_empty() {
        return Err(format!("fmuResourceLocation \"{loc}\" has no path"));
    }
    let decoded = percent_decode(path)
        .ok_or_else(|| format!("fmuResourceLocation \"{loc}\" has a bad %-escape"))?;
    Ok(PathBuf::from(decoded))
}

/// Decode `%XX` escapes (bytes, then UTF-8); `None` on a malformed escape or invalid UTF-8.
fn percent_decode(s: &str) -> Option<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = s.get(i + 1..i + 3)?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uri_forms() {
        let want = PathBuf::from("/tmp/a b/resources");
        for loc in [
            "file:///tmp/a%20b/resources",
            "file:/tmp/a%20b/resources",
            "file://localhost/tmp/a%20b/resources",
            "FILE:///tmp/a%20b/resources",
            "/tmp/a b/resources",
        ] {
            assert_eq!(resource_dir(loc).unwrap(), want, "{loc}");
        }
        assert_eq!(
            resource_dir("file:///tmp/%C3%A9t%C3%A9/").unwrap(),
            PathBuf::from("/tmp/été/")
        );
        assert_eq!(resource_dir("rel/dir").unwrap(), PathBuf::from("rel/dir"));
    }

    #[test]
    fn bad_locations_are_errors_not_panics() {
        for loc in [
            "",
            "http://example.com/r",
            "file://otherhost/r",
            "file:///bad%2",
            "file:///bad%zz",
            "file:///%ff%fe",
            "file://",
        ] {
            assert!(resource_dir(loc).is_err(), "{loc}");
        }
    }
}
