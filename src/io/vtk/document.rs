//! One VTK XML document being written: its elements and DataArrays, as text or as base64
//! binary (each array a UInt64 byte count and the little-endian values, encoded separately as
//! VTK's readers expect).

use base64::engine::general_purpose::STANDARD;
use base64::Engine;
use std::fmt::Write;

/// How the DataArrays of a VTK file are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum VtkEncoding {
    /// Text for small networks, binary from [`VtkEncoding::AUTO_BINARY_POINTS`] points on.
    #[default]
    Auto,
    /// Numbers as text (`format="ascii"`), readable in an editor.
    Ascii,
    /// Base64-encoded binary (`format="binary"`): exact, about a third of the text's size and
    /// much faster to read for large cells.
    Binary,
}

impl VtkEncoding {
    /// Networks with more points than this are written in binary by [`VtkEncoding::Auto`].
    pub const AUTO_BINARY_POINTS: usize = 20_000;

    /// Whether a file of `points` points is written in binary.
    pub fn binary(self, points: usize) -> bool {
        match self {
            VtkEncoding::Auto => points > Self::AUTO_BINARY_POINTS,
            VtkEncoding::Ascii => false,
            VtkEncoding::Binary => true,
        }
    }
}

/// A value type of a DataArray.
pub(super) trait Scalar: Copy {
    const TYPE: &'static str;
    fn text(self, s: &mut String);
    fn bytes(self, out: &mut Vec<u8>);
}

impl Scalar for f64 {
    const TYPE: &'static str = "Float64";
    fn text(self, s: &mut String) {
        // Shortest text that reads back to the same f64.
        let _ = write!(s, "{self:e}");
    }
    fn bytes(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

/// Integer types: their decimal text, and their little-endian bytes.
macro_rules! integer_scalar {
    ($($t:ty => $name:literal),*) => {$(
        impl Scalar for $t {
            const TYPE: &'static str = $name;
            fn text(self, s: &mut String) {
                let _ = write!(s, "{self}");
            }
            fn bytes(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
        }
    )*};
}

integer_scalar!(i64 => "Int64", i32 => "Int32", u8 => "UInt8");

/// A VTK XML document of one dataset type with one piece.
pub(super) struct Document {
    s: String,
    binary: bool,
    kind: &'static str,
}

impl Document {
    /// `<VTKFile type="{kind}">` with a comment, and the dataset's element; `binary` chooses
    /// the DataArray format.
    pub fn new(kind: &'static str, comment: &str, binary: bool) -> Self {
        let mut s = String::from("<?xml version=\"1.0\"?>\n");
        let _ = writeln!(s, "<!-- {comment} -->");
        let _ = writeln!(
            s,
            "<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" \
             header_type=\"UInt64\">\n<{kind}>"
        );
        Document { s, binary, kind }
    }

    /// An opening tag with its attributes, e.g. `Piece NumberOfPoints="4"`.
    pub fn open(&mut self, tag: &str) {
        let _ = writeln!(self.s, "<{tag}>");
    }

    /// The closing tag of element `name`.
    pub fn close(&mut self, name: &str) {
        let _ = writeln!(self.s, "</{name}>");
    }

    /// A DataArray `name` of `components` components per tuple.
    pub fn array<T: Scalar>(&mut self, name: &str, components: usize, values: &[T]) {
        let format = if self.binary { "binary" } else { "ascii" };
        let _ = writeln!(
            self.s,
            "<DataArray type=\"{}\" Name=\"{name}\" NumberOfComponents=\"{components}\" \
             format=\"{format}\">",
            T::TYPE
        );
        if self.binary {
            let mut data = Vec::with_capacity(8 * values.len());
            values.iter().for_each(|v| v.bytes(&mut data));
            let header = (data.len() as u64).to_le_bytes();
            STANDARD.encode_string(header, &mut self.s);
            STANDARD.encode_string(&data, &mut self.s);
            self.s.push('\n');
        } else {
            for tuple in values.chunks(components.max(1)) {
                for (k, v) in tuple.iter().enumerate() {
                    if k > 0 {
                        self.s.push(' ');
                    }
                    v.text(&mut self.s);
                }
                self.s.push('\n');
            }
        }
        self.s.push_str("</DataArray>\n");
    }

    /// The document, its elements closed.
    pub fn finish(mut self) -> String {
        let _ = write!(self.s, "</Piece>\n</{}>\n</VTKFile>\n", self.kind);
        self.s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary array is the UInt64 byte count and the values, each base64 on its own: the
    /// header of 3 f64 (24 bytes) is `GAAAAAAAAAA=`, and the values decode to what was written.
    #[test]
    fn a_binary_array_is_a_byte_count_and_the_values() {
        let mut d = Document::new("PolyData", "test", true);
        d.array("x", 3, &[1.5f64, -2.0, 1e-300]);
        let text = d.finish();
        let body = text
            .lines()
            .skip_while(|l| !l.starts_with("<DataArray"))
            .nth(1)
            .unwrap();
        assert!(body.starts_with("GAAAAAAAAAA="), "{body}");
        let data = STANDARD.decode(&body["GAAAAAAAAAA=".len()..]).unwrap();
        let values: Vec<f64> = data
            .chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(values, [1.5, -2.0, 1e-300]);
    }

    /// Text arrays hold one tuple per line and read back to the same numbers.
    #[test]
    fn a_text_array_reads_back_exactly() {
        let values = [0.1f64, 1.0 / 3.0, -2.5e-17, 6.02e23];
        let mut d = Document::new("PolyData", "test", false);
        d.array("x", 2, &values);
        let text = d.finish();
        let lines: Vec<&str> = text
            .lines()
            .skip_while(|l| !l.starts_with("<DataArray"))
            .skip(1)
            .take(2)
            .collect();
        let back: Vec<f64> = lines
            .iter()
            .flat_map(|l| l.split(' ').map(|v| v.parse::<f64>().unwrap()))
            .collect();
        assert_eq!(back, values);
        assert!(!VtkEncoding::Auto.binary(20_000));
        assert!(VtkEncoding::Auto.binary(20_001));
    }
}
