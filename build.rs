//! build.rs — turns `modelDescription/modelDescription.xml` (THE single source of
//! truth of the FMU interface) into Rust: value references, a variable table with
//! start values, the GUID, and the final XML text that `tyrekit package` ships.
//!
//! The build fails, naming the line of the XML, when the file is inconsistent:
//! duplicate names or value references, unknown types/causalities/units, a start
//! value missing where FMI 2.0 requires one (or present where it forbids one), a
//! ModelStructure that does not list exactly the outputs / initial unknowns, a log
//! category the code uses but the XML does not declare, or a variable list that
//! differs from what the Rust side binds (`src/fmi/spec.rs`).
//!
//! The GUID is a hash of the interface (model identifier and every variable's
//! name, value reference, type, causality, variability, initial, start and unit):
//! it changes exactly when the interface changes. The start values of
//! `spec::TYRE_DEPENDENT_STARTS` (`Fz`, `omega`) and `spec::CHOSEN_STARTS`
//! (`force_model`) are left out: `tyrekit package` sets them from the packaged
//! tyre and its options, and one library serves every packaged FMU.
//!
//! It also builds the FMU's shared library for the `tyrekit` binary to embed
//! (`packaging/build_lib.rs`, a nested cargo run over this package's library).
//! Must never: read anything but the XML and spec.rs (besides that nested
//! build), or produce code that allocates.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

#[path = "src/fmi/spec.rs"]
#[allow(dead_code)]
mod spec;

#[path = "packaging/build_lib.rs"]
mod build_lib;

const XML_PATH: &str = "modelDescription/modelDescription.xml";
const GUID_PLACEHOLDER: &str = "@GUID@";

struct Var {
    name: String,
    vr: u32,
    ty: &'static str,
    causality: String,
    variability: String,
    initial: Option<String>,
    start: Option<String>,
    unit: Option<String>,
    /// `min`/`max` of a Real (±inf when absent): the FMU refuses inputs outside.
    min: f64,
    max: f64,
    description: String,
    line: u32,
}

fn fail(msg: String) -> ! {
    eprintln!("error: {XML_PATH}: {msg}");
    eprintln!("(fix modelDescription/modelDescription.xml or src/fmi/spec.rs; see build.rs)");
    std::process::exit(1);
}

/// FNV-1a, 64 bit, from a chosen offset basis.
fn fnv1a(bytes: &[u8], basis: u64) -> u64 {
    let mut h = basis;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Upper-case Rust constant name for a variable name (`kappa_in` → `KAPPA_IN`).
fn const_name(name: &str) -> String {
    name.to_ascii_uppercase()
}

fn main() {
    println!("cargo:rerun-if-changed={XML_PATH}");
    println!("cargo:rerun-if-changed=src/fmi/spec.rs");
    println!("cargo:rerun-if-changed=build.rs");

    let text =
        std::fs::read_to_string(XML_PATH).unwrap_or_else(|e| fail(format!("cannot read: {e}")));
    let doc = roxmltree::Document::parse(&text)
        .unwrap_or_else(|e| fail(format!("not well-formed XML: {e}")));
    let line_of = |n: roxmltree::Node| doc.text_pos_at(n.range().start).row;
    let root = doc.root_element();
    if root.tag_name().name() != "fmiModelDescription" {
        fail("root element must be <fmiModelDescription>".into());
    }
    if root.attribute("fmiVersion") != Some("2.0") {
        fail("fmiVersion must be \"2.0\"".into());
    }
    if root.attribute("guid") != Some(GUID_PLACEHOLDER) {
        fail(format!(
            "guid must be the placeholder \"{GUID_PLACEHOLDER}\" (build.rs derives the GUID from the variable list)"
        ));
    }
    let child = |name: &str| root.children().find(|c| c.has_tag_name(name));
    let cs = child("CoSimulation").unwrap_or_else(|| fail("no <CoSimulation> element".into()));
    let model_identifier = cs
        .attribute("modelIdentifier")
        .unwrap_or_else(|| fail("<CoSimulation> has no modelIdentifier".into()))
        .to_string();
    let ident_ok = model_identifier
        .chars()
        .enumerate()
        .all(|(i, c)| c == '_' || c.is_ascii_alphabetic() || (i > 0 && c.is_ascii_digit()));
    if model_identifier.is_empty() || !ident_ok {
        fail(format!(
            "modelIdentifier \"{model_identifier}\" is not a C identifier"
        ));
    }
    for forbidden in ["canHandleMultipleSetPerTimeInstant"] {
        if doc.descendants().any(|n| n.attribute(forbidden).is_some()) {
            fail(format!(
                "attribute {forbidden} is rejected by fmi-sim's parser"
            ));
        }
    }

    // Units and log categories.
    let units: BTreeSet<String> = child("UnitDefinitions")
        .map(|u| {
            u.children()
                .filter(|c| c.has_tag_name("Unit"))
                .filter_map(|c| c.attribute("name").map(str::to_string))
                .collect()
        })
        .unwrap_or_default();
    let categories: BTreeSet<String> = child("LogCategories")
        .map(|u| {
            u.children()
                .filter(|c| c.has_tag_name("Category"))
                .filter_map(|c| c.attribute("name").map(str::to_string))
                .collect()
        })
        .unwrap_or_default();
    for c in spec::LOG_CATEGORIES {
        if !categories.contains(*c) {
            fail(format!(
                "<LogCategories> must declare \"{c}\" (the code logs with it)"
            ));
        }
    }

    // Variables.
    let mv = child("ModelVariables").unwrap_or_else(|| fail("no <ModelVariables>".into()));
    let mut vars: Vec<Var> = Vec::new();
    for sv in mv.children().filter(|c| c.is_element()) {
        let line = line_of(sv);
        if !sv.has_tag_name("ScalarVariable") {
            fail(format!(
                "line {line}: unexpected <{}> in <ModelVariables>",
                sv.tag_name().name()
            ));
        }
        if sv.children().any(|c| c.has_tag_name("Annotations")) {
            fail(format!(
                "line {line}: per-variable <Annotations> are rejected by fmi-sim's parser"
            ));
        }
        let name = sv
            .attribute("name")
            .unwrap_or_else(|| fail(format!("line {line}: ScalarVariable without name")))
            .to_string();
        let at = |k: &str| sv.attribute(k).map(str::to_string);
        let vr: u32 = at("valueReference")
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| {
                fail(format!(
                    "line {line}: {name}: valueReference missing or not an unsigned integer"
                ))
            });
        if vr > 4095 {
            fail(format!(
                "line {line}: {name}: valueReference {vr} > 4095 (keep the lookup table small)"
            ));
        }
        let elems: Vec<_> = sv.children().filter(|c| c.is_element()).collect();
        if elems.len() != 1 {
            fail(format!(
                "line {line}: {name}: needs exactly one type element, found {}",
                elems.len()
            ));
        }
        let te = elems[0];
        let ty: &'static str = match te.tag_name().name() {
            "Real" => "Real",
            "Integer" => "Integer",
            "Boolean" => "Boolean",
            "String" => "String",
            other => fail(format!(
                "line {line}: {name}: unknown or unsupported type <{other}> (Real, Integer, Boolean, String)"
            )),
        };
        let causality = at("causality").unwrap_or_else(|| "local".into());
        if !["input", "output", "parameter", "calculatedParameter"].contains(&causality.as_str()) {
            fail(format!(
                "line {line}: {name}: causality \"{causality}\" not supported (input, output, parameter, calculatedParameter)"
            ));
        }
        let variability = at("variability").unwrap_or_else(|| "continuous".into());
        if !["constant", "fixed", "tunable", "discrete", "continuous"]
            .contains(&variability.as_str())
        {
            fail(format!(
                "line {line}: {name}: unknown variability \"{variability}\""
            ));
        }
        if variability == "continuous" && ty != "Real" {
            fail(format!(
                "line {line}: {name}: only Real variables can be continuous"
            ));
        }
        let initial = at("initial");
        let start = te.attribute("start").map(str::to_string);
        // FMI 2.0 table of causality/initial: inputs and parameters need a start;
        // calculated outputs and calculatedParameters must not have one.
        let needs_start = matches!(causality.as_str(), "input" | "parameter")
            || matches!(initial.as_deref(), Some("exact") | Some("approx"));
        let forbids_start = initial.as_deref() == Some("calculated")
            || (initial.is_none()
                && matches!(causality.as_str(), "output" | "calculatedParameter"));
        if needs_start && start.is_none() {
            fail(format!(
                "line {line}: {name}: causality {causality} needs a start value"
            ));
        }
        if forbids_start && start.is_some() {
            fail(format!(
                "line {line}: {name}: a calculated variable must not have a start value"
            ));
        }
        if causality == "parameter" && !matches!(variability.as_str(), "fixed" | "tunable") {
            fail(format!(
                "line {line}: {name}: parameters must be fixed or tunable"
            ));
        }
        if let Some(s) = &start {
            let ok = match ty {
                "Real" => s
                    .trim()
                    .parse::<f64>()
                    .map(|x| x.is_finite())
                    .unwrap_or(false),
                "Integer" => s.trim().parse::<i32>().is_ok(),
                "Boolean" => matches!(s.trim(), "true" | "false" | "1" | "0"),
                _ => true,
            };
            if !ok {
                fail(format!(
                    "line {line}: {name}: start \"{s}\" is not a valid {ty}"
                ));
            }
            if matches!(ty, "Real" | "Integer") {
                let x: f64 = s.trim().parse().unwrap_or(f64::NAN);
                for (k, below) in [("min", true), ("max", false)] {
                    if let Some(b) = te.attribute(k).and_then(|b| b.parse::<f64>().ok()) {
                        if (below && x < b) || (!below && x > b) {
                            fail(format!("line {line}: {name}: start {s} outside {k} = {b}"));
                        }
                    }
                }
            }
        }
        let unit = te.attribute("unit").map(str::to_string);
        if ty == "Real" {
            match &unit {
                None => fail(format!("line {line}: {name}: Real variable without unit")),
                Some(u) if !units.contains(u) => fail(format!(
                    "line {line}: {name}: unit \"{u}\" is not in <UnitDefinitions>"
                )),
                _ => {}
            }
        }
        if sv
            .attribute("description")
            .is_none_or(|d| d.trim().is_empty())
        {
            fail(format!("line {line}: {name}: missing description"));
        }
        vars.push(Var {
            name,
            vr,
            ty,
            causality,
            variability,
            initial,
            start,
            unit,
            min: te
                .attribute("min")
                .and_then(|b| b.trim().parse::<f64>().ok())
                .unwrap_or(f64::NEG_INFINITY),
            max: te
                .attribute("max")
                .and_then(|b| b.trim().parse::<f64>().ok())
                .unwrap_or(f64::INFINITY),
            description: sv.attribute("description").unwrap_or("").to_string(),
            line,
        });
    }

    // Uniqueness.
    let mut names = BTreeMap::new();
    let mut consts = BTreeMap::new();
    let mut vrs = BTreeMap::new();
    for v in &vars {
        if let Some(l) = names.insert(v.name.clone(), v.line) {
            fail(format!(
                "line {}: duplicate variable name \"{}\" (first on line {l})",
                v.line, v.name
            ));
        }
        if let Some(other) = consts.insert(const_name(&v.name), v.name.clone()) {
            fail(format!(
                "line {}: \"{}\" and \"{other}\" map to the same Rust constant",
                v.line, v.name
            ));
        }
        if let Some(other) = vrs.insert(v.vr, v.name.clone()) {
            fail(format!(
                "line {}: valueReference {} of \"{}\" already used by \"{other}\" (aliases are not supported: every variable needs its own valueReference)",
                v.line, v.vr, v.name
            ));
        }
    }

    // The Rust side's expectations, both ways.
    for (name, ty, causality) in spec::BOUND_VARIABLES {
        match vars.iter().find(|v| v.name == *name) {
            None => fail(format!(
                "variable \"{name}\" ({ty}, {causality}) is bound by the Rust code (src/fmi/spec.rs) but not declared"
            )),
            Some(v) if v.ty != *ty || v.causality != *causality => fail(format!(
                "line {}: \"{name}\" is {} {} here but the Rust code binds it as {ty} {causality}",
                v.line, v.ty, v.causality
            )),
            _ => {}
        }
    }
    for v in &vars {
        if !spec::BOUND_VARIABLES.iter().any(|(n, _, _)| *n == v.name) {
            fail(format!(
                "line {}: variable \"{}\" is declared but the Rust code does not bind it (add it to src/fmi/spec.rs and handle it)",
                v.line, v.name
            ));
        }
    }

    // ModelStructure: Outputs = all outputs; InitialUnknowns = calculated outputs
    // and calculatedParameters (FMI 2.0, section 2.2.8, co-simulation).
    let ms = child("ModelStructure").unwrap_or_else(|| fail("no <ModelStructure>".into()));
    let listed = |tag: &str| -> BTreeSet<usize> {
        ms.children()
            .find(|c| c.has_tag_name(tag))
            .map(|o| {
                o.children()
                    .filter(|c| c.has_tag_name("Unknown"))
                    .map(|u| {
                        u.attribute("index")
                            .and_then(|i| i.parse().ok())
                            .unwrap_or_else(|| {
                                fail(format!(
                                    "line {}: Unknown without a valid index",
                                    line_of(u)
                                ))
                            })
                    })
                    .collect()
            })
            .unwrap_or_default()
    };
    let outputs: BTreeSet<usize> = vars
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == "output")
        .map(|(i, _)| i + 1)
        .collect();
    let initial_unknowns: BTreeSet<usize> = vars
        .iter()
        .enumerate()
        .filter(|(_, v)| {
            v.causality == "calculatedParameter"
                || (v.causality == "output"
                    && matches!(
                        v.initial.as_deref(),
                        None | Some("calculated") | Some("approx")
                    ))
        })
        .map(|(i, _)| i + 1)
        .collect();
    for (tag, want) in [
        ("Outputs", &outputs),
        ("InitialUnknowns", &initial_unknowns),
    ] {
        let got = listed(tag);
        if &got != want {
            fail(format!(
                "<ModelStructure><{tag}> lists indices {got:?}, expected {want:?} (1-based ScalarVariable positions)"
            ));
        }
    }

    // Tyre-dependent start values: Real inputs with a start value (packaging
    // rewrites it), left out of the GUID.
    for name in spec::TYRE_DEPENDENT_STARTS {
        match vars.iter().find(|v| v.name == *name) {
            Some(v) if v.ty == "Real" && v.causality == "input" && v.start.is_some() => {}
            _ => fail(format!(
                "\"{name}\" (spec::TYRE_DEPENDENT_STARTS) must be a Real input with a start value"
            )),
        }
    }
    // Chosen start values: String parameters whose start `tyrekit package`
    // picks from a fixed list (the XML's must be one of them), also left out.
    for (name, allowed) in spec::CHOSEN_STARTS {
        match vars.iter().find(|v| v.name == *name) {
            Some(v)
                if v.ty == "String"
                    && v.causality == "parameter"
                    && v.start.as_deref().is_some_and(|s| allowed.contains(&s)) => {}
            _ => fail(format!(
                "\"{name}\" (spec::CHOSEN_STARTS) must be a String parameter whose start is one of {allowed:?}"
            )),
        }
    }
    fn start_in_guid(v: &Var) -> &str {
        if spec::TYRE_DEPENDENT_STARTS.contains(&v.name.as_str()) {
            "tyre"
        } else if spec::CHOSEN_STARTS.iter().any(|(n, _)| *n == v.name) {
            "chosen"
        } else {
            v.start.as_deref().unwrap_or("")
        }
    }

    // GUID from the interface.
    let mut canon = format!("fmi2|{model_identifier}\n");
    for v in &vars {
        let _ = writeln!(
            canon,
            "{}|{}|{}|{}|{}|{}|{}|{}",
            v.name,
            v.vr,
            v.ty,
            v.causality,
            v.variability,
            v.initial.as_deref().unwrap_or(""),
            start_in_guid(v),
            v.unit.as_deref().unwrap_or("")
        );
    }
    let h1 = fnv1a(canon.as_bytes(), 0xcbf2_9ce4_8422_2325);
    let h2 = fnv1a(canon.as_bytes(), 0x84222325_cbf29ce4 ^ h1);
    let guid = format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        h1 >> 32,
        (h1 >> 16) & 0xffff,
        h1 & 0xffff,
        h2 >> 48,
        h2 & 0xffff_ffff_ffff
    );
    let final_xml = text.replacen(GUID_PLACEHOLDER, &guid, 1);
    // The FMU's shared library, for the binary to embed (packaging/build_lib.rs).
    println!("cargo:rerun-if-changed=packaging/build_lib.rs");
    build_lib::embed(&guid);

    // Generated Rust.
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// @generated by build.rs from {XML_PATH}. Do not edit."
    );
    let _ = writeln!(
        out,
        "/// GUID of this interface (hash of the variable list)."
    );
    let _ = writeln!(out, "pub const GUID: &str = {guid:?};");
    let _ = writeln!(out, "/// `modelIdentifier` of the co-simulation interface.");
    let _ = writeln!(
        out,
        "pub const MODEL_IDENTIFIER: &str = {model_identifier:?};"
    );
    let _ = writeln!(
        out,
        "/// The modelDescription.xml shipped in the FMU (GUID filled in)."
    );
    let _ = writeln!(
        out,
        "pub const MODEL_DESCRIPTION_XML: &str = include_str!(concat!(env!(\"OUT_DIR\"), \"/modelDescription.xml\"));"
    );
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    let mut slots = Vec::new();
    for v in &vars {
        let c = counts.entry(v.ty).or_insert(0);
        slots.push(*c);
        *c += 1;
    }
    for (ty, module) in [
        ("Real", "real"),
        ("Integer", "integer"),
        ("Boolean", "boolean"),
        ("String", "string"),
    ] {
        let _ = writeln!(out, "/// Storage slots of the {ty} variables.");
        let _ = writeln!(out, "pub mod {module} {{");
        let _ = writeln!(
            out,
            "    /// Number of {ty} variables.\n    pub const N: usize = {};",
            counts.get(ty).copied().unwrap_or(0)
        );
        for (v, s) in vars.iter().zip(&slots) {
            if v.ty == ty {
                let _ = writeln!(
                    out,
                    "    /// Slot of `{}`.\n    pub const {}: usize = {s};",
                    v.name,
                    const_name(&v.name)
                );
            }
        }
        let _ = writeln!(out, "}}");
    }
    let _ = writeln!(out, "/// Value references.");
    let _ = writeln!(out, "pub mod vr {{");
    for v in &vars {
        let _ = writeln!(
            out,
            "    /// `{}`.\n    pub const {}: u32 = {};",
            v.name,
            const_name(&v.name),
            v.vr
        );
    }
    let _ = writeln!(out, "}}");
    let _ = writeln!(out, "/// Every variable, in modelDescription order.");
    let _ = writeln!(out, "pub const VARIABLES: [VarInfo; {}] = [", vars.len());
    for (v, s) in vars.iter().zip(&slots) {
        let start = match (&v.start, v.ty) {
            (None, _) => "Start::None".to_string(),
            (Some(x), "Real") => {
                format!("Start::Real({:?})", x.trim().parse::<f64>().unwrap_or(0.0))
            }
            (Some(x), "Integer") => {
                format!("Start::Integer({})", x.trim().parse::<i32>().unwrap_or(0))
            }
            (Some(x), "Boolean") => format!("Start::Boolean({})", matches!(x.trim(), "true" | "1")),
            (Some(x), _) => format!("Start::String({x:?})"),
        };
        let bound = |x: f64| {
            if x == f64::INFINITY {
                "f64::INFINITY".to_string()
            } else if x == f64::NEG_INFINITY {
                "f64::NEG_INFINITY".to_string()
            } else {
                format!("{x:?}")
            }
        };
        let cap = |s: &str| {
            let mut c = s.chars();
            c.next()
                .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
                .unwrap_or_default()
        };
        let _ = writeln!(
            out,
            "    VarInfo {{ vr: {}, name: {:?}, ty: VarType::{}, slot: {s}, causality: Causality::{}, variability: Variability::{}, start: {start}, unit: {:?}, min: {}, max: {}, description: {:?} }},",
            v.vr,
            v.name,
            v.ty,
            cap(&v.causality),
            cap(&v.variability),
            v.unit.as_deref().unwrap_or(""),
            bound(v.min),
            bound(v.max),
            v.description
        );
    }
    let _ = writeln!(out, "];");
    let max_vr = vars.iter().map(|v| v.vr).max().unwrap_or(0);
    let mut table = vec![u16::MAX; max_vr as usize + 1];
    for (i, v) in vars.iter().enumerate() {
        table[v.vr as usize] = i as u16;
    }
    let _ = writeln!(
        out,
        "/// valueReference → index into [`VARIABLES`] (`u16::MAX` = unknown)."
    );
    let _ = writeln!(
        out,
        "pub const VR_TABLE: [u16; {}] = {table:?};",
        table.len()
    );

    let dir = std::env::var("OUT_DIR").unwrap_or_else(|_| fail("OUT_DIR not set".into()));
    let dir = std::path::Path::new(&dir);
    std::fs::write(dir.join("modelDescription.xml"), final_xml)
        .unwrap_or_else(|e| fail(format!("cannot write OUT_DIR/modelDescription.xml: {e}")));
    std::fs::write(dir.join("fmi_vars.rs"), out)
        .unwrap_or_else(|e| fail(format!("cannot write OUT_DIR/fmi_vars.rs: {e}")));
}
