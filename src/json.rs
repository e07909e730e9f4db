//! The JSON plumbing that scene files and input tracks share: text that
//! is no JSON at all, serde_json's errors sorted into "this field is
//! wrong" and "this is not JSON", field paths written as the messages name
//! them, and objects refused when given as arrays. It knows nothing of
//! either format, so both loaders and their one error type
//! (`crate::load_error`) sit above it.

use std::fmt::Write as _;

use serde::Deserialize;

/// What is wrong with JSON text that serde_json would report obscurely: a
/// UTF-8 byte-order mark, or no text at all. (line, column, message).
pub(crate) fn text_problem(text: &str) -> Option<(usize, usize, String)> {
    if text.starts_with('\u{feff}') {
        let message = "the text starts with a byte-order mark (U+FEFF), which JSON does not allow: save it as UTF-8 without one";
        return Some((1, 1, message.into()));
    }
    if text.trim().is_empty() {
        // where serde_json stops, in its words, and why
        let (line, column) = (text.matches('\n').count() + 1, text.rsplit('\n').next().map_or(0, |l| l.chars().count()));
        return Some((line, column, "EOF while parsing a value: the text is empty (or only blanks); expected an object".into()));
    }
    None
}

/// A serde_json error as the JSON loaders (scenes, input tracks) report it.
pub(crate) enum JsonFault {
    /// A field is unknown, of the wrong type, or a number beyond any float.
    Invalid { field: String, message: String },
    /// The text is not JSON.
    Syntax { line: usize, column: usize, message: String },
}

/// Classifies a serde_json error raised in `field` (None: the top level,
/// named `top` in the message).
pub(crate) fn classify_json_error(field: Option<String>, inner: serde_json::Error, top: &str) -> JsonFault {
    let (line, column) = (inner.line(), inner.column());
    // serde_json's message ends with " at line L column C"; we place the
    // position ourselves.
    let full = inner.to_string();
    let suffix = format!(" at line {line} column {column}");
    let message = one_line(full.strip_suffix(&suffix).unwrap_or(&full));

    use serde_json::error::Category;
    let number_out_of_range = message.starts_with("number out of range");
    match (inner.classify(), field) {
        // A number too large for any float (like 1e999) is valid JSON
        // grammar but not a usable value: blame the field it is in.
        (Category::Syntax, Some(field)) if number_out_of_range => {
            JsonFault::Invalid { field, message: format!("number out of range, must be finite (line {line}, column {column})") }
        }
        // Unknown field, wrong type, out-of-range integer, ...
        (Category::Data, field) => JsonFault::Invalid {
            field: field.unwrap_or_else(|| top.to_string()),
            message: format!("{message} (line {line}, column {column})"),
        },
        (Category::Syntax | Category::Eof | Category::Io, field) => JsonFault::Syntax {
            line,
            column,
            message: match field {
                Some(field) => format!("{message} (in {field})"),
                None => message,
            },
        },
    }
}

/// Writes a serde_path_to_error path as `bodies[3].shape.half_extents[1]`;
/// `None` for the top level.
pub(crate) fn path_string(path: &serde_path_to_error::Path) -> Option<String> {
    use serde_path_to_error::Segment;
    let mut out = String::new();
    for segment in path.iter() {
        match segment {
            Segment::Seq { index } => {
                let _ = write!(out, "[{index}]");
            }
            Segment::Map { key } | Segment::Enum { variant: key } => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(&one_line(key));
            }
            // A map key not read yet (say, a syntax error right after a
            // comma): the enclosing path is all there is to say.
            Segment::Unknown => {}
        }
    }
    if out.is_empty() {
        None
    } else {
        Some(out)
    }
}

/// Escapes control characters (newlines in a field name, say) so that an
/// error message stays on one line.
pub(crate) fn one_line(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// Deserializes `T` from a JSON object only. Serde's derived structs also
/// accept an array of field values in declaration order, which neither a
/// scene file nor a track ever means; this refuses it with "expected a JSON object".
pub(crate) struct Obj<T>(pub(crate) T);

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Obj<T> {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct ObjectVisitor<T>(std::marker::PhantomData<T>);

        impl<'de, T: Deserialize<'de>> serde::de::Visitor<'de> for ObjectVisitor<T> {
            type Value = T;

            fn expecting(&self, formatter: &mut std::fmt::Formatter) -> std::fmt::Result {
                formatter.write_str("a JSON object")
            }

            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
                T::deserialize(serde::de::value::MapAccessDeserializer::new(map))
            }
        }

        deserializer.deserialize_map(ObjectVisitor(std::marker::PhantomData)).map(Obj)
    }
}
