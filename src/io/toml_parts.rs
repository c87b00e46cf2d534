//! A large TOML model parsed in parts on all threads.
//!
//! toml reads a document at about 20–30 MB/s on one core (the L non-woven's 16 MB in 0.5–0.9 s).
//! A model file is mostly `[[nodes]]` and `[[fibers]]` entries, and a line holding exactly one
//! of those headers starts a self-contained TOML document: whatever follows it up to the next
//! header belongs to that one entry. So the text is cut at such lines into parts of about
//! equal size, the parts are parsed side by side and their entries concatenated in order.
//!
//! The parts' result is used only when it must be the whole document's: every part parses,
//! each part holds exactly as many nodes and fibers as it has header lines (an inline array, or
//! a header line inside a multi-line string, breaks the count), and every other field is given
//! in one part at most (a table or key split over parts). Otherwise — and for every error, so
//! that its line and column are the document's — the caller parses the whole text.

use crate::model::ModelDescription;
use rayon::prelude::*;

/// Documents from this size are parsed in parts (below it the threads cost more than they
/// save).
pub(super) const PARTS_FROM_BYTES: usize = 1 << 20;

/// The header lines a document is cut at.
const HEADERS: [&str; 2] = ["[[nodes]]", "[[fibers]]"];

/// The description of `text` parsed in up to `parts` parts, or `None` where the parts cannot
/// stand for the whole (see the module): then only the whole document's parse answers.
pub(super) fn parse_in_parts(text: &str, parts: usize) -> Option<ModelDescription> {
    let cuts = cut_points(text, parts);
    if cuts.len() < 3 {
        return None;
    }
    let parsed: Vec<Option<(ModelDescription, [usize; 2])>> = cuts
        .par_windows(2)
        .map(|w| {
            let part = &text[w[0]..w[1]];
            let description: ModelDescription = toml::from_str(part).ok()?;
            Some((description, header_lines(part)))
        })
        .collect();
    let mut whole = ModelDescription::default();
    for part in parsed {
        let (description, [nodes, fibers]) = part?;
        if description.nodes.len() != nodes || description.fibers.len() != fibers {
            return None;
        }
        append(&mut whole, description)?;
    }
    Some(whole)
}

/// Byte offsets that cut `text` into up to `parts` pieces at header lines, with 0 first and
/// the length last: the first header line at or after each k-th fraction of the text.
fn cut_points(text: &str, parts: usize) -> Vec<usize> {
    let mut cuts = vec![0];
    for k in 1..parts {
        let from = (text.len() * k / parts).max(cuts[cuts.len() - 1] + 1);
        match next_header_line(text, from) {
            Some(at) => cuts.push(at),
            None => break,
        }
    }
    cuts.push(text.len());
    cuts
}

/// The start of the first line at or after byte `from` that is a header of [`HEADERS`].
fn next_header_line(text: &str, from: usize) -> Option<usize> {
    let bytes = text.as_bytes();
    let mut start = if from == 0 || bytes[from - 1] == b'\n' {
        from
    } else {
        from + bytes[from..].iter().position(|&b| b == b'\n')? + 1
    };
    for line in text[start..].split_inclusive('\n') {
        if header(line).is_some() {
            return Some(start);
        }
        start += line.len();
    }
    None
}

/// Which of [`HEADERS`] `line` is exactly (trailing blanks, a carriage return or the newline
/// allowed).
fn header(line: &str) -> Option<usize> {
    let line = line.trim_end();
    HEADERS.iter().position(|h| *h == line)
}

/// The `[[nodes]]` and `[[fibers]]` header lines of `part`.
fn header_lines(part: &str) -> [usize; 2] {
    let mut counts = [0; 2];
    for k in part.lines().filter_map(header) {
        counts[k] += 1;
    }
    counts
}

/// Appends a later part's nodes and fibers to `whole` and moves its other fields over, or
/// `None` if a field other than those two is given in both.
fn append(whole: &mut ModelDescription, part: ModelDescription) -> Option<()> {
    // Every field by name: a field added to the description fails to compile here.
    let ModelDescription {
        name,
        materials,
        nodes,
        fibers,
        supports,
        loads,
        contact,
        contacts,
        cell,
    } = part;
    whole.nodes.extend(nodes);
    whole.fibers.extend(fibers);
    once(&mut whole.name, name)?;
    once(&mut whole.contact, contact)?;
    once(&mut whole.cell, cell)?;
    once_list(&mut whole.materials, materials)?;
    once_list(&mut whole.supports, supports)?;
    once_list(&mut whole.loads, loads)?;
    once_list(&mut whole.contacts, contacts)
}

fn once<T>(whole: &mut Option<T>, part: Option<T>) -> Option<()> {
    if part.is_some() {
        if whole.is_some() {
            return None;
        }
        *whole = part;
    }
    Some(())
}

fn once_list<T>(whole: &mut Vec<T>, part: Vec<T>) -> Option<()> {
    if !part.is_empty() {
        if !whole.is_empty() {
            return None;
        }
        *whole = part;
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::parse_toml_as;

    /// A model of `n` nodes and fibers of two nodes each, with a cell and supports at the end.
    fn model_text(n: usize) -> String {
        let mut t = String::from(
            "name = \"parts\"\n\n[[materials]]\nname = \"fiber\"\nyoung = 1.5e9\npoisson = 0.4\n\n",
        );
        for i in 1..=n {
            t += &format!(
                "[[nodes]]\nid = {i}\nx = [{}, 0.5, 1e-5]\n\n",
                i as f64 * 1e-4
            );
        }
        for i in 1..n {
            t += &format!(
                "[[fibers]]\nid = {i}\nnodes = [{i}, {}]\nradius = 1e-5\nmaterial = \"fiber\"\n\n",
                i + 1
            );
        }
        t += "[[supports]]\nnode = 1\ndofs = [\"all\"]\n\n[cell]\nsize = [0.1, 0.1]\n";
        t
    }

    fn whole(text: &str) -> ModelDescription {
        parse_toml_as(text, "test.toml").unwrap()
    }

    /// The parts give the whole document's description, entry for entry, for any number of
    /// parts, with the cuts at header lines and in order.
    #[test]
    fn the_parts_are_the_whole_document() {
        let text = model_text(2_000);
        let expected = whole(&text);
        assert_eq!(expected.nodes.len(), 2_000);
        for parts in [2, 3, 4, 7, 16] {
            let cuts = cut_points(&text, parts);
            assert_eq!(cuts.len(), parts + 1, "{parts} parts");
            assert!(cuts.windows(2).all(|w| w[0] < w[1]));
            for &c in &cuts[1..parts] {
                assert!(
                    header(text[c..].lines().next().unwrap()).is_some(),
                    "cut at {c}"
                );
            }
            assert_eq!(parse_in_parts(&text, parts).as_ref(), Some(&expected));
        }
        // With Windows line ends too.
        let crlf = text.replace('\n', "\r\n");
        assert_eq!(parse_in_parts(&crlf, 4).as_ref(), Some(&expected));
    }

    /// A document with no header line past its start is not cut.
    #[test]
    fn a_document_without_headers_is_not_cut() {
        assert_eq!(cut_points("name = \"x\"\n", 4), vec![0, 11]);
        assert!(parse_in_parts("name = \"x\"\n[cell]\nsize = [1.0, 1.0]\n", 4).is_none());
    }

    /// Where the parts cannot stand for the whole they give nothing: an inline node array
    /// beside the headers, a header line inside a multi-line string, a table given in two
    /// parts, a syntax error in a later part.
    #[test]
    fn the_parts_give_way_where_the_whole_decides() {
        let text = model_text(400);
        // Inline nodes filling the first half: the first part holds them and no header, so
        // it parses and only the count gives it away.
        let entries: Vec<String> = (10_000..13_000)
            .map(|i| format!("{{ id = {i}, x = [0.0, 0.0, 0.0] }}"))
            .collect();
        let inline = text.replacen(
            "[[materials]]",
            &format!("nodes = [{}]\n\n[[materials]]", entries.join(",\n")),
            1,
        );
        assert!(toml::from_str::<ModelDescription>(&inline).is_err());
        let first = &inline[..cut_points(&inline, 2)[1]];
        assert_eq!(
            toml::from_str::<ModelDescription>(first)
                .unwrap()
                .nodes
                .len(),
            3_000
        );
        assert!(parse_in_parts(&inline, 2).is_none());

        let in_string = text.replacen(
            "name = \"fiber\"",
            &format!("name = \"\"\"fi\n{}ber\"\"\"", "[[nodes]]\n".repeat(5)),
            1,
        );
        let in_string_whole = whole(&in_string);
        assert!(in_string_whole.materials[0].name.contains("[[nodes]]"));
        assert!(parse_in_parts(&in_string, 4).is_none());

        let mid = text.len() / 2;
        let at = next_header_line(&text, mid).unwrap();
        let two_cells = format!(
            "{}[cell]\nsize = [0.2, 0.2]\n\n{}",
            &text[..at],
            &text[at..]
        );
        assert!(toml::from_str::<ModelDescription>(&two_cells).is_err());
        assert!(parse_in_parts(&two_cells, 2).is_none());

        let broken = format!("{}[[nodes]]\nid = = 3\n\n{}", &text[..at], &text[at..]);
        assert!(parse_in_parts(&broken, 4).is_none());
    }
}
