//! A small writer for Mitsuba 3's XML: indented elements, escaped attributes,
//! numbers in their shortest round-trip form.

use glam::{Affine2, Vec3};

/// An XML document being written, element by element.
#[derive(Default)]
pub(super) struct Xml {
    text: String,
    depth: usize,
}

impl Xml {
    pub(super) fn new() -> Self {
        Self::default()
    }

    /// A fragment whose elements start `depth` levels in.
    pub(super) fn with_depth(depth: usize) -> Self {
        Self {
            text: String::new(),
            depth,
        }
    }

    /// Appends a fragment written with [`Self::with_depth`].
    pub(super) fn append(&mut self, fragment: Xml) {
        self.text.push_str(&fragment.text);
    }

    /// The text so far.
    pub(super) fn text(&self) -> &str {
        &self.text
    }

    fn indent(&mut self) {
        for _ in 0..self.depth {
            self.text.push_str("    ");
        }
    }

    fn tag(&mut self, name: &str, attributes: &[(&str, &str)], end: &str) {
        self.indent();
        self.text.push('<');
        self.text.push_str(name);
        for (key, value) in attributes {
            self.text.push(' ');
            self.text.push_str(key);
            self.text.push_str("=\"");
            self.text.push_str(&escape(value));
            self.text.push('"');
        }
        self.text.push_str(end);
        self.text.push('\n');
    }

    /// `<name attributes>`; close it with [`Self::close`].
    pub(super) fn open(&mut self, name: &str, attributes: &[(&str, &str)]) {
        self.tag(name, attributes, ">");
        self.depth += 1;
    }

    /// `</name>`.
    pub(super) fn close(&mut self, name: &str) {
        self.depth -= 1;
        self.indent();
        self.text.push_str("</");
        self.text.push_str(name);
        self.text.push_str(">\n");
    }

    /// `<name attributes/>`.
    pub(super) fn leaf(&mut self, name: &str, attributes: &[(&str, &str)]) {
        self.tag(name, attributes, "/>");
    }

    /// `<!-- text -->` (a `--` in the text would end the comment: it is spaced out).
    pub(super) fn comment(&mut self, text: &str) {
        self.indent();
        self.text.push_str("<!-- ");
        self.text.push_str(&text.replace("--", "- -"));
        self.text.push_str(" -->\n");
    }

    /// A named property: `<kind name="name" value="value"/>`.
    pub(super) fn property(&mut self, kind: &str, name: &str, value: &str) {
        self.leaf(kind, &[("name", name), ("value", value)]);
    }

    pub(super) fn float(&mut self, name: &str, value: f32) {
        self.property("float", name, &number(value));
    }

    pub(super) fn integer(&mut self, name: &str, value: u64) {
        self.property("integer", name, &value.to_string());
    }

    pub(super) fn string(&mut self, name: &str, value: &str) {
        self.property("string", name, value);
    }

    pub(super) fn rgb(&mut self, name: &str, value: Vec3) {
        self.property("rgb", name, &vector(value));
    }

    /// `<transform name="name"><matrix value="…"/></transform>` for a 4×4
    /// matrix given row by row.
    pub(super) fn matrix(&mut self, name: &str, rows: [[f32; 4]; 4]) {
        let values: Vec<String> = rows.iter().flatten().map(|&x| number(x)).collect();
        self.open("transform", &[("name", name)]);
        self.leaf("matrix", &[("value", &values.join(" "))]);
        self.close("transform");
    }

    /// A texture's `to_uv`: the 2D affine map in the 4×4 matrix Mitsuba reads it
    /// from (its upper-left 2×2 block and the translation column).
    pub(super) fn texture_transform(&mut self, map: Affine2) {
        let (m, t) = (map.matrix2, map.translation);
        self.matrix(
            "to_uv",
            [
                [m.x_axis.x, m.y_axis.x, 0.0, t.x],
                [m.x_axis.y, m.y_axis.y, 0.0, t.y],
                [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ],
        );
    }

    pub(super) fn finish(self) -> String {
        self.text
    }
}

/// `x` in its shortest form that reads back as the same `f32`; `-0` as `0`.
pub(super) fn number(x: f32) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x}")
    }
}

/// `x, y, z`.
pub(super) fn vector(v: Vec3) -> String {
    format!("{}, {}, {}", number(v.x), number(v.y), number(v.z))
}

fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' => out.push_str("&#10;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attributes_are_escaped_and_numbers_short() {
        let mut xml = Xml::new();
        xml.open("bsdf", &[("type", "diffuse"), ("id", "a\"<b>&'c")]);
        xml.rgb("reflectance", Vec3::new(0.7, -0.0, 1e-7));
        xml.comment("x -- y");
        xml.close("bsdf");
        assert_eq!(
            xml.finish(),
            "<bsdf type=\"diffuse\" id=\"a&quot;&lt;b&gt;&amp;&apos;c\">\n    \
             <rgb name=\"reflectance\" value=\"0.7, 0, 0.0000001\"/>\n    \
             <!-- x - - y -->\n</bsdf>\n"
        );
    }
}
