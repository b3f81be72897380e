//! A request's query: the API's own parameters taken out, the rest the
//! command line's flags ([`Flags`]), checked for shape before the command
//! line's parser sees them.

use crate::http::Request;

/// Command-line flags by name without the dashes, each with its value (""
/// for a switch such as `all-samples`), in the order given.
pub type Flags = Vec<(String, String)>;

/// The longest flag name and value taken.
const MAX_NAME: usize = 40;
const MAX_VALUE: usize = 256;

/// `request`'s parameters: those named in `own` by name, the others as
/// flags; or why not (a name given twice, or not a flag's shape).
pub(crate) fn split(
    request: &Request,
    own: &[&str],
) -> Result<(Vec<(String, String)>, Flags), String> {
    let mut mine = Vec::new();
    let mut flags = Flags::new();
    for (name, value) in &request.query {
        if name == "token" {
            continue;
        }
        if request.query.iter().filter(|(n, _)| n == name).count() > 1 {
            return Err(format!("{} is given twice", shorten(name)));
        }
        match own.contains(&name.as_str()) {
            true => mine.push((name.clone(), value.clone())),
            false => flags.push((checked_name(name)?, checked_value(name, value)?)),
        }
    }
    Ok((mine, flags))
}

/// The value of `name` among `pairs`.
pub(crate) fn get<'a>(pairs: &'a [(String, String)], name: &str) -> Option<&'a str> {
    pairs
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, v)| v.as_str())
}

fn checked_name(name: &str) -> Result<String, String> {
    let shaped = !name.is_empty()
        && name.len() <= MAX_NAME
        && name.starts_with(|c: char| c.is_ascii_lowercase())
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-');
    match shaped {
        true => Ok(name.to_owned()),
        false => Err(format!(
            "\"{}\" is not a flag's name (lower-case letters, digits and -)",
            shorten(name)
        )),
    }
}

fn checked_value(name: &str, value: &str) -> Result<String, String> {
    match value.len() <= MAX_VALUE && !value.chars().any(char::is_control) {
        true => Ok(value.to_owned()),
        false => Err(format!(
            "{name}: the value is too long or holds control characters"
        )),
    }
}

/// `text` cut to 40 characters for an error message.
pub(crate) fn shorten(text: &str) -> String {
    match text.char_indices().nth(40) {
        Some((at, _)) => format!("{}…", &text[..at]),
        None => text.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(query: &[(&str, &str)]) -> Request {
        Request {
            path: "/".into(),
            query: query
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
        }
    }

    #[test]
    fn own_parameters_and_flags_are_told_apart_and_checked() {
        let r = request(&[
            ("token", "t"),
            ("id", "1"),
            ("spp", "4"),
            ("all-samples", ""),
        ]);
        let (mine, flags) = split(&r, &["id"]).unwrap();
        assert_eq!(get(&mine, "id"), Some("1"));
        assert_eq!(
            flags,
            [
                ("spp".into(), "4".into()),
                ("all-samples".into(), String::new())
            ]
        );
        for bad in [("../etc", "1"), ("Spp", "1"), ("", "1"), ("spp", "\n")] {
            assert!(split(&request(&[bad]), &[]).is_err(), "{bad:?}");
        }
        assert!(split(&request(&[("spp", "1"), ("spp", "2")]), &[])
            .unwrap_err()
            .contains("twice"));
        let long = "x".repeat(300);
        assert!(split(&request(&[("spp", &long)]), &[]).is_err());
    }
}
