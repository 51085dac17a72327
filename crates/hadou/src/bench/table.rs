//! The one table type of `hadou bench`: rows of named cells, printed as text in aligned columns
//! and as JSON objects keyed by the cells' names. Every bench table is a [`Report`]: the fields
//! that describe the whole measurement and one or more [`Table`]s.

use serde_json::{Map, Value};

/// Which side of its column a cell's text keeps to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Align {
    /// Padded on the right.
    Left,
    /// Padded on the left.
    Right,
}

/// A column of a table's text.
#[derive(Clone, Debug)]
pub struct Column {
    /// The header line's text.
    pub header: String,
    /// Width in characters: shorter texts are padded to it, longer ones are not cut.
    pub width: usize,
    /// Which side the text keeps to.
    pub align: Align,
    /// What stands between this column and the one before it (nothing before the first).
    pub gap: &'static str,
}

impl Column {
    /// A left-aligned column, one space after the one before it.
    pub fn left(header: impl Into<String>, width: usize) -> Self {
        Self { header: header.into(), width, align: Align::Left, gap: " " }
    }

    /// A right-aligned column, one space after the one before it.
    pub fn right(header: impl Into<String>, width: usize) -> Self {
        Self { header: header.into(), width, align: Align::Right, gap: " " }
    }

    /// The same column with `gap` before it instead of one space.
    pub fn after(self, gap: &'static str) -> Self {
        Self { gap, ..self }
    }

    fn pad(&self, text: &str) -> String {
        match self.align {
            Align::Left => format!("{text:<width$}", width = self.width),
            Align::Right => format!("{text:>width$}", width = self.width),
        }
    }
}

/// One cell of a row: its name (its key in the row's JSON object), its JSON value and its text.
/// A cell without a JSON value shows only in the text (a label, a ratio); one without a text
/// only in the JSON (a list of sub-rows, a value the text shows combined with another).
#[derive(Clone, Debug)]
pub struct Cell {
    /// The JSON key.
    pub name: &'static str,
    /// The JSON value.
    pub json: Option<Value>,
    /// The text, as printed in its column.
    pub text: Option<String>,
}

impl Cell {
    /// A cell shown in both the text and the JSON.
    pub fn new(name: &'static str, json: impl Into<Value>, text: impl Into<String>) -> Self {
        Self { name, json: Some(json.into()), text: Some(text.into()) }
    }

    /// A cell only the JSON has.
    pub fn json(name: &'static str, json: impl Into<Value>) -> Self {
        Self { name, json: Some(json.into()), text: None }
    }

    /// A cell only the text shows.
    pub fn text(name: &'static str, text: impl Into<String>) -> Self {
        Self { name, json: None, text: Some(text.into()) }
    }
}

/// A row: its cells, the text cells in column order.
pub type Row = Vec<Cell>;

/// `rows` as a JSON array of objects, one per row, keyed by the cells' names.
pub fn rows_json(rows: &[Row]) -> Value {
    let object = |row: &Row| {
        let cells = row.iter().filter_map(|c| Some((c.name.to_string(), c.json.clone()?)));
        Value::Object(cells.collect::<Map<String, Value>>())
    };
    Value::Array(rows.iter().map(object).collect())
}

/// A table: a title, text columns and rows of named cells.
#[derive(Clone, Debug, Default)]
pub struct Table {
    /// The key its rows are listed under in the report's JSON; `None` for a table only the text
    /// shows.
    pub key: Option<&'static str>,
    /// The text before the header line (each line ending in a newline; may be empty).
    pub title: String,
    /// The text columns; none for a table only the JSON has. A row's text cells fill them in
    /// order; cells beyond the last column are laid out as the last column.
    pub columns: Vec<Column>,
    /// The rows.
    pub rows: Vec<Row>,
}

impl Table {
    /// The title, the header line and a line per row; only the title when there are no columns.
    pub fn to_text(&self) -> String {
        let mut out = self.title.clone();
        if self.columns.is_empty() {
            return out;
        }
        out += &self.line(self.columns.iter().map(|c| c.header.as_str()));
        for row in &self.rows {
            out += &self.line(row.iter().filter_map(|c| c.text.as_deref()));
        }
        out
    }

    /// The rows as JSON (see [`rows_json`]).
    pub fn rows_json(&self) -> Value {
        rows_json(&self.rows)
    }

    fn line<'a>(&self, texts: impl Iterator<Item = &'a str>) -> String {
        let mut out = String::new();
        for (i, text) in texts.enumerate() {
            let Some(column) = self.columns.get(i).or(self.columns.last()) else { break };
            if i > 0 {
                out += column.gap;
            }
            out += &column.pad(text);
        }
        out + "\n"
    }
}

/// What one `hadou bench` table prints: the fields that describe the whole measurement (the
/// backend, how time was measured, …) and its tables, printed one after the other as text and
/// listed under their keys beside the fields as JSON.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// The JSON fields beside the tables' rows.
    pub fields: Vec<(&'static str, Value)>,
    /// The tables, in the order the text prints them.
    pub tables: Vec<Table>,
}

impl Report {
    /// The tables as plain text.
    pub fn to_text(&self) -> String {
        self.tables.iter().map(Table::to_text).collect()
    }

    /// The report as one JSON object: its fields, and each keyed table's rows under its key.
    pub fn to_json(&self) -> Value {
        let mut object: Map<String, Value> =
            self.fields.iter().map(|(k, v)| (k.to_string(), v.clone())).collect();
        for t in &self.tables {
            if let Some(key) = t.key {
                object.insert(key.to_string(), t.rows_json());
            }
        }
        Value::Object(object)
    }
}
