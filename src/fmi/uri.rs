//! The `fmuResourceLocation` URI → a local folder.
//!
//! Accepted: `file:/abs`, `file:///abs`, `file:////abs` (fmi4cpp/ecos), `file://localhost/abs`,
//! percent-encoding (`%20`, UTF-8 bytes), and a bare absolute path (non-conforming importers).
//! NULL or `""` means "no resources". Nothing is chopped by a fixed count of characters.
use crate::error::{Error, Result};
use std::path::PathBuf;

/// The folder named by `uri`, `Ok(None)` when the importer gave none.
pub fn resource_dir(uri: Option<&str>) -> Result<Option<PathBuf>> {
    let Some(uri) = uri else { return Ok(None) };
    let uri = uri.trim();
    if uri.is_empty() {
        return Ok(None);
    }
    let path = if uri.len() >= 5 && uri[..5].eq_ignore_ascii_case("file:") {
        let rest = &uri[5..];
        // A query or fragment ends the path ('?' and '#' inside a path are percent-encoded).
        let rest = &rest[..rest.find(['?', '#']).unwrap_or(rest.len())];
        let path = if let Some(after) = rest.strip_prefix("//") {
            // An authority: empty (file:///…) or localhost; anything else is a remote host.
            let end = after.find('/').unwrap_or(after.len());
            let host = &after[..end];
            if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
                return Err(Error::input(format!("resource location {uri}: the host \"{host}\" is not this machine; only local file URIs are supported")));
            }
            &after[end..]
        } else {
            rest
        };
        if !path.starts_with('/') {
            return Err(Error::input(format!("resource location {uri}: a file URI must hold an absolute path")));
        }
        percent_decode(path)
    } else if uri.starts_with('/') {
        uri.as_bytes().to_vec()
    } else if let Some(i) = uri.find(':') {
        return Err(Error::input(format!("resource location {uri}: the scheme \"{}\" is not supported, only file:", &uri[..i])));
    } else {
        return Err(Error::input(format!("resource location {uri}: not a file URI and not an absolute path")));
    };
    // Collapse repeated leading slashes (file:////tmp → /tmp).
    let start = path.iter().take_while(|&&b| b == b'/').count();
    let path = &path[start.saturating_sub(1)..];
    Ok(Some(bytes_to_path(path)))
}

/// `%XX` → the byte; a `%` not followed by two hex digits is kept literally.
fn percent_decode(s: &str) -> Vec<u8> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%'
            && i + 2 < b.len()
            && let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2]))
        {
            out.push(h * 16 + l);
            i += 3;
            continue;
        }
        out.push(b[i]);
        i += 1;
    }
    out
}

fn hex(c: u8) -> Option<u8> {
    match c {
        b'0'..=b'9' => Some(c - b'0'),
        b'a'..=b'f' => Some(c - b'a' + 10),
        b'A'..=b'F' => Some(c - b'A' + 10),
        _ => None,
    }
}

#[cfg(unix)]
fn bytes_to_path(b: &[u8]) -> PathBuf {
    use std::os::unix::ffi::OsStrExt;
    PathBuf::from(std::ffi::OsStr::from_bytes(b))
}

#[cfg(not(unix))]
fn bytes_to_path(b: &[u8]) -> PathBuf {
    let s = String::from_utf8_lossy(b);
    // file:///C:/dir → C:/dir
    let s = match s.as_bytes() {
        [b'/', d, b':', ..] if d.is_ascii_alphabetic() => s[1..].to_string(),
        _ => s.to_string(),
    };
    PathBuf::from(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(uri: &str) -> String {
        resource_dir(Some(uri)).unwrap().unwrap().to_str().unwrap().to_string()
    }

    #[test]
    fn the_forms_importers_send() {
        assert_eq!(dir("file:///tmp/tmpab12/resources"), "/tmp/tmpab12/resources");
        assert_eq!(dir("file:/tmp/x/resources"), "/tmp/x/resources");
        assert_eq!(dir("file:////tmp/ecos_osc/resources"), "/tmp/ecos_osc/resources");
        assert_eq!(dir("file://localhost/tmp/x/resources/"), "/tmp/x/resources/");
        assert_eq!(dir("FILE://LocalHost/tmp/x"), "/tmp/x");
        assert_eq!(dir("file:///dir%20with%20space/%C3%BC/unz/resources"), "/dir with space/ü/unz/resources");
        assert_eq!(dir("file:///a%2fb%25c"), "/a/b%c");
        assert_eq!(dir("/plain/path/resources"), "/plain/path/resources");
        assert_eq!(dir("file:///tmp/x?query#frag"), "/tmp/x");
    }

    #[test]
    fn none_and_empty_mean_no_resources() {
        assert_eq!(resource_dir(None).unwrap(), None);
        assert_eq!(resource_dir(Some("")).unwrap(), None);
        assert_eq!(resource_dir(Some("  ")).unwrap(), None);
    }

    #[test]
    fn a_stray_percent_is_kept() {
        assert_eq!(dir("file:///a%zzb%2"), "/a%zzb%2");
        assert_eq!(dir("file:///a%"), "/a%");
    }

    #[test]
    fn refused_forms_say_why() {
        assert!(resource_dir(Some("file://server/share")).unwrap_err().message().contains("host \"server\""));
        assert!(resource_dir(Some("http://example.com/r")).unwrap_err().message().contains("scheme \"http\""));
        assert!(resource_dir(Some("file:relative/path")).unwrap_err().message().contains("absolute"));
        assert!(resource_dir(Some("relative/path")).unwrap_err().message().contains("not a file URI"));
    }
}
