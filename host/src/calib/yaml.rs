//! A YAML document as a tree whose every key knows its line: OpenCV's and Kalibr's files are
//! YAML, and an error must name the line of the key it is about. `yaml-rust2` parses; this
//! module only keeps the parser's line of each node.

use std::path::Path;

use yaml_rust2::parser::{Event, MarkedEventReceiver, Parser};
use yaml_rust2::scanner::Marker;

use super::CalibError;

/// One YAML value and the line it starts on (1-based).
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    pub value: Value,
    pub line: usize,
}

/// The shapes a calibration file uses (tags are not kept: the readers go by keys).
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Scalar(String),
    Seq(Vec<Node>),
    Map(Vec<Entry>),
}

/// One key of a mapping, with the line the key stands on.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    pub key: String,
    pub line: usize,
    pub node: Node,
}

/// Parses the first document of `text`; the error message names the line.
pub fn parse(text: &str) -> Result<Node, String> {
    let mut builder = Builder::default();
    Parser::new_from_str(text)
        .load(&mut builder, false)
        .map_err(|e| e.to_string())?;
    if let Some(e) = builder.error {
        return Err(e);
    }
    builder
        .root
        .ok_or_else(|| "the file holds no YAML document".to_owned())
}

impl Node {
    /// The entry `key` of a mapping; `None` for a missing key or a node that is no mapping.
    pub fn get(&self, key: &str) -> Option<&Entry> {
        match &self.value {
            Value::Map(entries) => entries.iter().find(|e| e.key == key),
            _ => None,
        }
    }

    /// A scalar's text.
    pub fn as_str(&self) -> Option<&str> {
        match &self.value {
            Value::Scalar(s) => Some(s),
            _ => None,
        }
    }

    /// A scalar as a finite number, or the error naming `key`, the line and the text.
    pub fn number(&self, key: &str, path: &Path) -> Result<f64, CalibError> {
        let text = self.as_str().ok_or_else(|| {
            CalibError::key(
                path,
                key,
                Some(self.line),
                "must be a number, not a list or map",
            )
        })?;
        super::number(text).ok_or_else(|| {
            CalibError::key(
                path,
                key,
                Some(self.line),
                format!("is `{text}`, not a finite number"),
            )
        })
    }

    /// A sequence of finite numbers (`key[i]` names a bad item).
    pub fn numbers(&self, key: &str, path: &Path) -> Result<Vec<f64>, CalibError> {
        match &self.value {
            Value::Seq(items) => items
                .iter()
                .enumerate()
                .map(|(i, item)| item.number(&format!("{key}[{i}]"), path))
                .collect(),
            _ => Err(CalibError::key(
                path,
                key,
                Some(self.line),
                "must be a list of numbers",
            )),
        }
    }
}

/// A mapping or sequence still being filled, with its line and (mappings) the key whose
/// value comes next.
enum Open {
    Seq(usize, Vec<Node>),
    Map(usize, Vec<Entry>, Option<(String, usize)>),
}

#[derive(Default)]
struct Builder {
    open: Vec<Open>,
    root: Option<Node>,
    error: Option<String>,
}

impl Builder {
    fn attach(&mut self, node: Node) {
        match self.open.last_mut() {
            None => {
                self.root.get_or_insert(node);
            }
            Some(Open::Seq(_, items)) => items.push(node),
            Some(Open::Map(_, entries, pending)) => match pending.take() {
                Some((key, line)) => entries.push(Entry { key, line, node }),
                None => match node.value {
                    Value::Scalar(key) => *pending = Some((key, node.line)),
                    _ => {
                        self.error.get_or_insert(format!(
                            "line {}: a key must be a plain name, not a list or map",
                            node.line
                        ));
                    }
                },
            },
        }
    }
}

impl MarkedEventReceiver for Builder {
    fn on_event(&mut self, ev: Event, mark: Marker) {
        let line = mark.line();
        match ev {
            Event::Scalar(text, ..) => self.attach(Node {
                value: Value::Scalar(text),
                line,
            }),
            Event::SequenceStart(..) => self.open.push(Open::Seq(line, Vec::new())),
            Event::MappingStart(..) => self.open.push(Open::Map(line, Vec::new(), None)),
            Event::SequenceEnd | Event::MappingEnd => {
                let node = match self.open.pop() {
                    Some(Open::Seq(line, items)) => Node {
                        value: Value::Seq(items),
                        line,
                    },
                    Some(Open::Map(line, entries, _)) => Node {
                        value: Value::Map(entries),
                        line,
                    },
                    None => return,
                };
                self.attach(node);
            }
            Event::Alias(_) => {
                self.error
                    .get_or_insert(format!("line {line}: YAML aliases (*name) are not read"));
            }
            Event::Nothing
            | Event::StreamStart
            | Event::StreamEnd
            | Event::DocumentStart
            | Event::DocumentEnd => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_carry_their_lines() {
        let root = parse("a: 1\nb:\n  c: [1, 2,\n      x]\n").unwrap();
        assert_eq!(root.get("a").unwrap().line, 1);
        let b = &root.get("b").unwrap().node;
        let c = b.get("c").unwrap();
        assert_eq!(c.line, 3);
        let err = c.node.numbers("b.c", Path::new("f.yaml")).unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.contains("f.yaml") && msg.contains("line 4") && msg.contains("b.c[2]"),
            "{msg}"
        );
    }

    #[test]
    fn a_syntax_error_names_its_line() {
        let err = parse("a: 1\nb: [1, 2\nc: 3\n").unwrap_err();
        assert!(err.contains("line"), "{err}");
    }
}
