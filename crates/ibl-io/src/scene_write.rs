//! Writing an edited scene file back (`docs/SCENES.md`) so that its comments and layout survive:
//! the original text is parsed as a TOML document, and only the fields whose value differs between
//! the description as read and as edited are rewritten, each in place with its own comments.
//!
//! The three-way comparison (text, description as read, description as edited) keeps the file
//! minimal: a field the file leaves to its default is not written out just because the parsed
//! description holds the default; a field the edit removed is removed. Changed floats are written
//! with the shortest decimal that reads back to the same f32 (`0.777`, not the f64 expansion
//! `0.7770000100135803` of the f32), so `ibl render` of the written file parses exactly the
//! edited description (tested).

use ibl_scene::SceneDescription;
use toml_edit::{DocumentMut, Item, Value};

/// Why an edited scene could not be written as text.
#[derive(Debug, thiserror::Error)]
pub enum SceneWriteError {
    /// The original text is not a TOML document.
    #[error("the scene file's text is not TOML: {0}")]
    Parse(String),
    /// A description could not be expressed as TOML.
    #[error("the scene cannot be written as TOML: {0}")]
    Serialize(String),
}

/// The text of `original_text` with the changes from `original` to `edited` applied.
pub fn edited_scene_text(
    original_text: &str,
    original: &SceneDescription,
    edited: &SceneDescription,
) -> Result<String, SceneWriteError> {
    let mut document: DocumentMut = original_text
        .parse()
        .map_err(|e: toml_edit::TomlError| SceneWriteError::Parse(e.to_string()))?;
    let serialize = |d: &SceneDescription| {
        toml_edit::ser::to_document(d).map_err(|e| SceneWriteError::Serialize(e.to_string()))
    };
    // Both sides shortened alike, so a float field the file leaves to its default (an f32
    // such as 0.04, whose f64 is 0.03999999910593033) compares equal to itself.
    let mut old = serialize(original)?;
    shorten_floats(old.as_item_mut());
    let mut new = serialize(edited)?;
    shorten_floats(new.as_item_mut());
    merge_table(
        document.as_item_mut(),
        Some(old.as_item()),
        new.as_item(),
        true,
    );
    Ok(document.to_string())
}

/// Rewrites every float as the shortest decimal of its f32 value.
fn shorten_floats(item: &mut Item) {
    match item {
        Item::Value(v) => shorten_value(v),
        Item::Table(t) => t.iter_mut().for_each(|(_, i)| shorten_floats(i)),
        Item::ArrayOfTables(a) => a
            .iter_mut()
            .for_each(|t| t.iter_mut().for_each(|(_, i)| shorten_floats(i))),
        Item::None => {}
    }
}

fn shorten_value(v: &mut Value) {
    match v {
        Value::Float(f) => {
            let short = format!("{}", *f.value() as f32);
            if let Ok(parsed) = short.parse::<f64>() {
                *v = Value::from(parsed);
            }
        }
        Value::Array(a) => a.iter_mut().for_each(shorten_value),
        Value::InlineTable(t) => t.iter_mut().for_each(|(_, v)| shorten_value(v)),
        _ => {}
    }
}

/// A value's text without its surrounding whitespace and comments.
fn bare(item: &Item) -> String {
    match item {
        Item::Value(v) => {
            let mut v = v.clone();
            v.decor_mut().clear();
            v.to_string()
        }
        other => other.to_string(),
    }
}

/// Merges `new` into `doc` where `old` (the serialised original) differs from it.
fn merge_table(doc: &mut Item, old: Option<&Item>, new: &Item, top_level: bool) {
    let Some(new_table) = new.as_table_like() else {
        return;
    };
    let old_table = old.and_then(Item::as_table_like);
    let Some(doc_table) = doc.as_table_like_mut() else {
        return;
    };
    let keys: Vec<String> = new_table.iter().map(|(k, _)| k.to_string()).collect();
    for key in &keys {
        let Some(new_item) = new_table.get(key) else {
            continue;
        };
        let old_item = old_table.and_then(|t| t.get(key));
        if let Some(doc_item) = doc_table.get_mut(key) {
            merge_item(doc_item, old_item, new_item);
        } else if old_item.is_some() && new_item.is_table_like() {
            // A table the file leaves to its defaults: write only the fields that changed.
            let mut fresh = if top_level {
                Item::Table(toml_edit::Table::new())
            } else {
                // Nested tables read best inline: `material = { kind = "glossy", ... }`.
                Item::Value(Value::InlineTable(toml_edit::InlineTable::new()))
            };
            merge_table(&mut fresh, old_item, new_item, false);
            if fresh.as_table_like().is_some_and(|t| !t.is_empty()) {
                doc_table.insert(key, fresh);
            }
        } else if old_item.is_none_or(|o| bare(o) != bare(new_item)) {
            let inserted = if top_level || !new_item.is_table() {
                new_item.clone()
            } else {
                match new_item.clone().into_value() {
                    Ok(v) => Item::Value(v),
                    Err(item) => item,
                }
            };
            doc_table.insert(key, inserted);
        }
    }
    let gone: Vec<String> = doc_table
        .iter()
        .map(|(k, _)| k.to_string())
        .filter(|k| new_table.get(k).is_none())
        .collect();
    for key in gone {
        doc_table.remove(&key);
    }
}

/// The tables of an array of tables, or of an array of inline tables (what the serialiser
/// writes for `[[object]]`); `None` for anything else.
fn tables(item: &Item) -> Option<Vec<toml_edit::Table>> {
    match item {
        Item::ArrayOfTables(a) => Some(a.iter().cloned().collect()),
        Item::Value(Value::Array(a)) => a
            .iter()
            .map(|v| v.as_inline_table().map(|t| t.clone().into_table()))
            .collect(),
        _ => None,
    }
}

fn merge_item(doc: &mut Item, old: Option<&Item>, new: &Item) {
    if doc.is_table_like() && new.is_table_like() {
        merge_table(doc, old, new, false);
        return;
    }
    if let (Item::ArrayOfTables(d), Some(n)) = (&mut *doc, tables(new)) {
        let o = old.and_then(tables);
        let count = n.len();
        for (i, new_table) in n.iter().enumerate() {
            let new_item = Item::Table(new_table.clone());
            let old_item = o
                .as_ref()
                .and_then(|o| o.get(i))
                .map(|t| Item::Table(t.clone()));
            match d.get_mut(i) {
                Some(table) => {
                    let mut item = Item::Table(std::mem::take(table));
                    merge_table(&mut item, old_item.as_ref(), &new_item, false);
                    if let Item::Table(t) = item {
                        *table = t;
                    }
                }
                None => d.push(new_table.clone()),
            }
        }
        while d.len() > count {
            d.remove(d.len() - 1);
        }
        return;
    }
    if old.is_some_and(|o| bare(o) == bare(new)) {
        return;
    }
    match (&mut *doc, new) {
        (Item::Value(d), Item::Value(n)) => {
            let decor = d.decor().clone();
            *d = n.clone();
            *d.decor_mut() = decor;
        }
        _ => *doc = new.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"# A comment that must survive.
version = 1

[probe]
file = "probe.exr"   # relative to this file

[[object]]
name = "bunny"
shape = "sphere"
radius = 0.5
translate = [0.0, -0.777, -1.2]  # on the ground
material = { kind = "diffuse", albedo = [0.75, 0.75, 0.75] }
"#;

    #[test]
    fn only_edited_fields_change() {
        let original = SceneDescription::from_toml(SCENE).expect("valid");
        let mut edited = original.clone();
        edited.object[0].translate = Some([0.25, -0.777, -1.5]);
        edited.object[0].rotate_deg = Some([30.0, 0.0, 0.0]);
        edited.object[0].material = Some(ibl_scene::description::MaterialDescription {
            kind: ibl_scene::description::MaterialKind::Glossy,
            albedo: Some([0.5, 0.4, 0.3]),
            specular: Some([0.2, 0.2, 0.2]),
            exponent: Some(80.0),
        });
        edited.lighting.lights = 32;
        let text = edited_scene_text(SCENE, &original, &edited).expect("writes");
        assert!(text.contains("# A comment that must survive."), "{text}");
        assert!(text.contains("# relative to this file"), "{text}");
        assert!(
            text.contains("translate = [0.25, -0.777, -1.5]  # on the ground"),
            "{text}"
        );
        assert!(text.contains("rotate_deg = [30.0, 0.0, 0.0]"), "{text}");
        assert!(!text.contains("0.7770000"), "{text}");
        assert!(
            !text.contains("radiance_scale"),
            "defaults stay out: {text}"
        );
        let back = SceneDescription::from_toml(&text).expect("reads back");
        assert_eq!(back, edited);
    }

    #[test]
    fn an_unedited_scene_is_written_unchanged() {
        let original = SceneDescription::from_toml(SCENE).expect("valid");
        let text = edited_scene_text(SCENE, &original, &original).expect("writes");
        assert_eq!(text, SCENE);
    }
}
