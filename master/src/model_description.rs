//! Typed `modelDescription.xml` (FMI 2.0.x standard, section 2.2 "FMI Description Schema"), parsed
//! with serde (quick-xml). Only what a co-simulation importer needs is kept; unknown elements and
//! attributes are ignored, as the standard allows vendor annotations.

use serde::Deserialize;
use std::collections::HashMap;

/// `fmiModelDescription` (FMI 2.0 section 2.2.1).
#[derive(Debug, Clone, Deserialize)]
pub struct ModelDescription {
    #[serde(rename = "@fmiVersion")]
    pub fmi_version: String,
    #[serde(rename = "@modelName")]
    pub model_name: String,
    #[serde(rename = "@guid")]
    pub guid: String,
    #[serde(rename = "@description", default)]
    pub description: Option<String>,
    #[serde(rename = "@generationTool", default)]
    pub generation_tool: Option<String>,
    #[serde(rename = "@variableNamingConvention", default)]
    pub variable_naming_convention: Option<String>,
    #[serde(rename = "CoSimulation", default)]
    pub co_simulation: Option<CoSimulation>,
    #[serde(rename = "ModelExchange", default)]
    pub model_exchange: Option<ModelExchange>,
    #[serde(rename = "UnitDefinitions", default)]
    pub unit_definitions: Option<UnitDefinitions>,
    #[serde(rename = "TypeDefinitions", default)]
    pub type_definitions: Option<TypeDefinitions>,
    #[serde(rename = "LogCategories", default)]
    pub log_categories: Option<LogCategories>,
    #[serde(rename = "DefaultExperiment", default)]
    pub default_experiment: Option<DefaultExperiment>,
    #[serde(rename = "VendorAnnotations", default)]
    pub vendor_annotations: Option<VendorAnnotations>,
    #[serde(rename = "ModelVariables", default)]
    pub model_variables: ModelVariables,
    #[serde(rename = "ModelStructure", default)]
    pub model_structure: Option<ModelStructure>,
}

/// `CoSimulation` capability flags (FMI 2.0 section 4.3.1).
#[derive(Debug, Clone, Deserialize)]
pub struct CoSimulation {
    #[serde(rename = "@modelIdentifier")]
    pub model_identifier: String,
    #[serde(rename = "@needsExecutionTool", default)]
    pub needs_execution_tool: bool,
    #[serde(rename = "@canHandleVariableCommunicationStepSize", default)]
    pub can_handle_variable_communication_step_size: bool,
    #[serde(rename = "@canInterpolateInputs", default)]
    pub can_interpolate_inputs: bool,
    #[serde(rename = "@maxOutputDerivativeOrder", default)]
    pub max_output_derivative_order: u32,
    #[serde(rename = "@canRunAsynchronuously", default)]
    pub can_run_asynchronuously: bool,
    #[serde(rename = "@canBeInstantiatedOnlyOncePerProcess", default)]
    pub can_be_instantiated_only_once_per_process: bool,
    #[serde(rename = "@canNotUseMemoryManagementFunctions", default)]
    pub can_not_use_memory_management_functions: bool,
    #[serde(rename = "@canGetAndSetFMUstate", default)]
    pub can_get_and_set_fmu_state: bool,
    #[serde(rename = "@canSerializeFMUstate", default)]
    pub can_serialize_fmu_state: bool,
    #[serde(rename = "@providesDirectionalDerivative", default)]
    pub provides_directional_derivative: bool,
}

/// `ModelExchange` (only its presence and identifier matter to a CS master).
#[derive(Debug, Clone, Deserialize)]
pub struct ModelExchange {
    #[serde(rename = "@modelIdentifier")]
    pub model_identifier: String,
}

#[derive(Debug, Clone, Default, Deserialize)]
pub struct UnitDefinitions {
    #[serde(rename = "Unit", default)]
    pub units: Vec<Unit>,
}

/// `Unit` with its optional `BaseUnit` (FMI 2.0 section 2.2.2).
#[derive(Debug, Clone, Deserialize)]
pub struct Unit {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "BaseUnit", default)]
    pub base_unit: Option<BaseUnit>,
    #[serde(rename = "DisplayUnit", default)]
    pub display_units: Vec<DisplayUnit>,
}

/// A display unit of a unit (FMI 2.0, sec. 2.2.2): value_display = factor * value + offset.
#[derive(Debug, Clone, Deserialize)]
pub struct DisplayUnit {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "@factor", default = "one")]
    pub factor: f64,
    #[serde(rename = "@offset", default)]
    pub offset: f64,
}

/// SI exponents plus factor/offset: value_SI = factor * value + offset.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
pub struct BaseUnit {
    #[serde(rename = "@kg", default)]
    pub kg: i32,
    #[serde(rename = "@m", default)]
    pub m: i32,
    #[serde(rename = "@s", default)]
    pub s: i32,
    #[serde(rename = "@A", default)]
    pub a: i32,
    #[serde(rename = "@K", default)]
    pub k: i32,
    #[serde(rename = "@mol", default)]
    pub mol: i32,
    #[serde(rename = "@cd", default)]
    pub cd: i32,
    #[serde(rename = "@rad", default)]
    pub rad: i32,
    #[serde(rename = "@factor", default = "one")]
    pub factor: f64,
    #[serde(rename = "@offset", default)]
    pub offset: f64,
}

fn one() -> f64 {
    1.0
}

impl BaseUnit {
    /// The SI exponent vector (kg, m, s, A, K, mol, cd, rad).
    pub fn exponents(&self) -> [i32; 8] {
        [
            self.kg, self.m, self.s, self.a, self.k, self.mol, self.cd, self.rad,
        ]
    }
}

#[derive(Debug, Clone, Default, Deserialize)]
pub struct TypeDefinitions {
    #[serde(rename = "SimpleType", default)]
    pub simple_types: Vec<SimpleType>,
}

/// `SimpleType` (FMI 2.0 section 2.2.3); only the Real unit is used for declared types.
#[derive(Debug, Clone, Deserialize)]
pub struct SimpleType {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "Real", default)]
    pub real: Option<RealAttributes>,
}

#[derive(Debug, Clone, Default, Deserialize)]
pub struct LogCategories {
    #[serde(rename = "Category", default)]
    pub categories: Vec<LogCategory>,
}

#[derive(Debug, Clone, Deserialize)]
pub struct LogCategory {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "@description", default)]
    pub description: Option<String>,
}

/// `VendorAnnotations` (FMI 2.0 section 2.2.6): one `Tool` element per tool; only the tool
/// "shipsim"'s content is read.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct VendorAnnotations {
    #[serde(rename = "Tool", default)]
    pub tools: Vec<Tool>,
}

/// One tool's annotations. For "shipsim": the couplings (an output and the parameter that
/// scales it), written by our FMUs' export layer.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct Tool {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "Couplings", default)]
    pub couplings: Option<Couplings>,
}

#[derive(Debug, Clone, Default, Deserialize)]
pub struct Couplings {
    #[serde(rename = "Coupling", default)]
    pub couplings: Vec<Coupling>,
}

/// An output and the parameter that scales it: a connected output whose gain is 0 carries
/// only zeros (`shipsim check` warns).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
pub struct Coupling {
    #[serde(rename = "@output")]
    pub output: String,
    #[serde(rename = "@gain")]
    pub gain: String,
}

/// `DefaultExperiment` (FMI 2.0 section 2.2.5).
#[derive(Debug, Clone, Default, Deserialize)]
pub struct DefaultExperiment {
    #[serde(rename = "@startTime", default)]
    pub start_time: Option<f64>,
    #[serde(rename = "@stopTime", default)]
    pub stop_time: Option<f64>,
    #[serde(rename = "@tolerance", default)]
    pub tolerance: Option<f64>,
    #[serde(rename = "@stepSize", default)]
    pub step_size: Option<f64>,
}

#[derive(Debug, Clone, Default, Deserialize)]
pub struct ModelVariables {
    #[serde(rename = "ScalarVariable", default)]
    pub variables: Vec<ScalarVariable>,
}

pub use fmi2::{Causality, Initial, Variability};

/// Attributes of a `Real` variable or type.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct RealAttributes {
    #[serde(rename = "@declaredType", default)]
    pub declared_type: Option<String>,
    #[serde(rename = "@quantity", default)]
    pub quantity: Option<String>,
    #[serde(rename = "@unit", default)]
    pub unit: Option<String>,
    #[serde(rename = "@displayUnit", default)]
    pub display_unit: Option<String>,
    #[serde(rename = "@start", default)]
    pub start: Option<f64>,
    #[serde(rename = "@min", default)]
    pub min: Option<f64>,
    #[serde(rename = "@max", default)]
    pub max: Option<f64>,
    #[serde(rename = "@nominal", default)]
    pub nominal: Option<f64>,
    #[serde(rename = "@derivative", default)]
    pub derivative: Option<u32>,
}

#[derive(Debug, Clone, Default, Deserialize)]
pub struct IntegerAttributes {
    #[serde(rename = "@declaredType", default)]
    pub declared_type: Option<String>,
    #[serde(rename = "@start", default)]
    pub start: Option<i32>,
    #[serde(rename = "@min", default)]
    pub min: Option<i32>,
    #[serde(rename = "@max", default)]
    pub max: Option<i32>,
}

#[derive(Debug, Clone, Default, Deserialize)]
pub struct BooleanAttributes {
    #[serde(rename = "@declaredType", default)]
    pub declared_type: Option<String>,
    #[serde(rename = "@start", default)]
    pub start: Option<bool>,
}

#[derive(Debug, Clone, Default, Deserialize)]
pub struct StringAttributes {
    #[serde(rename = "@declaredType", default)]
    pub declared_type: Option<String>,
    #[serde(rename = "@start", default)]
    pub start: Option<String>,
}

/// `ScalarVariable` (FMI 2.0 section 2.2.7); exactly one of the type elements is present.
#[derive(Debug, Clone, Deserialize)]
pub struct ScalarVariable {
    #[serde(rename = "@name")]
    pub name: String,
    #[serde(rename = "@valueReference")]
    pub value_reference: u32,
    #[serde(rename = "@description", default)]
    pub description: Option<String>,
    #[serde(rename = "@causality", default)]
    pub causality: Causality,
    #[serde(rename = "@variability", default)]
    pub variability: Variability,
    #[serde(rename = "@initial", default)]
    pub initial: Option<Initial>,
    #[serde(rename = "Real", default)]
    pub real: Option<RealAttributes>,
    #[serde(rename = "Integer", default)]
    pub integer: Option<IntegerAttributes>,
    #[serde(rename = "Boolean", default)]
    pub boolean: Option<BooleanAttributes>,
    #[serde(rename = "String", default)]
    pub string: Option<StringAttributes>,
    #[serde(rename = "Enumeration", default)]
    pub enumeration: Option<IntegerAttributes>,
}

/// The base type of a variable. Enumerations travel through fmi2Get/SetInteger.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
    String,
    Enumeration,
}

impl VarType {
    pub fn name(self) -> &'static str {
        match self {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
            VarType::String => "String",
            VarType::Enumeration => "Enumeration",
        }
    }
    /// Types that share one FMI get/set function family can be connected.
    pub fn connectable_with(self, other: VarType) -> bool {
        use VarType::*;
        matches!(
            (self, other),
            (Real, Real)
                | (Integer, Integer)
                | (Enumeration, Enumeration)
                | (Integer, Enumeration)
                | (Enumeration, Integer)
                | (Boolean, Boolean)
                | (String, String)
        )
    }
}

impl std::fmt::Display for VarType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl ScalarVariable {
    pub fn var_type(&self) -> Option<VarType> {
        if self.real.is_some() {
            Some(VarType::Real)
        } else if self.integer.is_some() {
            Some(VarType::Integer)
        } else if self.boolean.is_some() {
            Some(VarType::Boolean)
        } else if self.string.is_some() {
            Some(VarType::String)
        } else if self.enumeration.is_some() {
            Some(VarType::Enumeration)
        } else {
            None
        }
    }

    /// The effective `initial` attribute, with the defaults of FMI 2.0 section 2.2.7 (table of
    /// causality x variability combinations).
    pub fn effective_initial(&self) -> Option<Initial> {
        if self.initial.is_some() {
            return self.initial;
        }
        use Causality as C;
        use Variability as V;
        match (self.causality, self.variability) {
            (C::Parameter, _) => Some(Initial::Exact),
            (C::CalculatedParameter, _) => Some(Initial::Calculated),
            (C::Input, _) | (C::Independent, _) => None,
            (_, V::Constant) => Some(Initial::Exact),
            (C::Output, _) | (C::Local, _) => Some(Initial::Calculated),
        }
    }

    /// The start value as text (for display).
    pub fn start_text(&self) -> Option<String> {
        if let Some(r) = &self.real {
            return r.start.map(|v| format!("{v}"));
        }
        if let Some(i) = &self.integer {
            return i.start.map(|v| v.to_string());
        }
        if let Some(i) = &self.enumeration {
            return i.start.map(|v| v.to_string());
        }
        if let Some(b) = &self.boolean {
            return b.start.map(|v| v.to_string());
        }
        if let Some(s) = &self.string {
            return s.start.clone();
        }
        None
    }

    pub fn has_start(&self) -> bool {
        self.start_text().is_some()
    }

    /// May the variable be set with fmi2SetXXX in the state "Instantiated"
    /// (FMI 2.0 section 4.2.4, state machine of a co-simulation slave; FMPy follows the same rule).
    pub fn settable_in_instantiated(&self) -> bool {
        self.variability != Variability::Constant
            && matches!(
                self.effective_initial(),
                Some(Initial::Exact) | Some(Initial::Approx)
            )
    }

    /// May the variable be set in "InitializationMode".
    pub fn settable_in_initialization_mode(&self) -> bool {
        (self.variability != Variability::Constant
            && self.effective_initial() == Some(Initial::Exact))
            || self.causality == Causality::Input
    }

    /// May the variable be set in "StepComplete" (between steps): inputs, and tunable parameters.
    pub fn settable_in_step_mode(&self) -> bool {
        self.causality == Causality::Input
            || (self.causality == Causality::Parameter && self.variability == Variability::Tunable)
    }
}

/// `ModelStructure` (FMI 2.0 section 2.2.8).
#[derive(Debug, Clone, Default, Deserialize)]
pub struct ModelStructure {
    #[serde(rename = "Outputs", default)]
    pub outputs: Option<UnknownList>,
    #[serde(rename = "Derivatives", default)]
    pub derivatives: Option<UnknownList>,
    #[serde(rename = "InitialUnknowns", default)]
    pub initial_unknowns: Option<UnknownList>,
}

#[derive(Debug, Clone, Default, Deserialize)]
pub struct UnknownList {
    #[serde(rename = "Unknown", default)]
    pub unknowns: Vec<Unknown>,
}

/// `Unknown`: a 1-based index into ModelVariables plus its dependencies (None = depends on all).
#[derive(Debug, Clone, Deserialize)]
pub struct Unknown {
    #[serde(rename = "@index")]
    pub index: usize,
    #[serde(rename = "@dependencies", default)]
    pub dependencies: Option<String>,
}

impl Unknown {
    /// Parsed dependency indices; `None` means "depends on everything" (attribute absent).
    pub fn dependency_indices(&self) -> Option<Vec<usize>> {
        self.dependencies.as_ref().map(|d| {
            d.split_whitespace()
                .filter_map(|x| x.parse::<usize>().ok())
                .collect()
        })
    }
}

impl ModelDescription {
    /// Parses the XML text. Errors carry quick-xml's message (position where known).
    pub fn parse(xml: &str) -> Result<Self, quick_xml::DeError> {
        quick_xml::de::from_str(xml)
    }

    /// The couplings the tool "shipsim" annotates (empty for FMUs that declare none).
    pub fn couplings(&self) -> &[Coupling] {
        self.vendor_annotations
            .iter()
            .flat_map(|v| &v.tools)
            .find(|t| t.name == "shipsim")
            .and_then(|t| t.couplings.as_ref())
            .map_or(&[], |c| c.couplings.as_slice())
    }

    /// The first variable name declared twice, if any (names are unique, FMI 2.0, sec. 2.2.7).
    pub fn duplicate_variable_name(&self) -> Option<&str> {
        let mut seen = std::collections::HashSet::new();
        self.model_variables
            .variables
            .iter()
            .map(|v| v.name.as_str())
            .find(|&n| !seen.insert(n))
    }

    /// Name -> index map of the model variables.
    pub fn variable_index(&self) -> HashMap<String, usize> {
        self.model_variables
            .variables
            .iter()
            .enumerate()
            .map(|(i, v)| (v.name.clone(), i))
            .collect()
    }

    pub fn unit(&self, name: &str) -> Option<&Unit> {
        self.unit_definitions
            .as_ref()
            .and_then(|u| u.units.iter().find(|x| x.name == name))
    }

    /// The unit of a Real variable, following `declaredType` when the variable has none.
    pub fn real_unit<'a>(&'a self, v: &'a ScalarVariable) -> Option<&'a str> {
        let r = v.real.as_ref()?;
        r.unit
            .as_deref()
            .or_else(|| self.real_declared_type(v)?.unit.as_deref())
    }

    /// The `Real` element of a Real variable's `declaredType` (FMI 2.0, sec. 2.2.3), which
    /// supplies the unit, display unit, min and max the variable leaves out.
    pub fn real_declared_type(&self, v: &ScalarVariable) -> Option<&RealAttributes> {
        let dt = v.real.as_ref()?.declared_type.as_ref()?;
        self.type_definitions
            .as_ref()?
            .simple_types
            .iter()
            .find(|t| &t.name == dt)?
            .real
            .as_ref()
    }

    /// Does an input variable have a direct feed-through to any output (ModelStructure)?
    /// Used to detect algebraic loops. Unknown dependencies count as feed-through
    /// (FMI 2.0 section 2.2.8: a missing `dependencies` attribute means dependence on all).
    pub fn output_depends_on(&self, output_index0: usize, input_index0: usize) -> bool {
        let Some(ms) = &self.model_structure else {
            return true;
        };
        let Some(outs) = &ms.outputs else {
            return true;
        };
        match outs.unknowns.iter().find(|u| u.index == output_index0 + 1) {
            None => true,
            Some(u) => match u.dependency_indices() {
                None => true,
                Some(deps) => deps.contains(&(input_index0 + 1)),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const XML: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="M" guid="{abc}">
  <CoSimulation modelIdentifier="M" canHandleVariableCommunicationStepSize="true" canGetAndSetFMUstate="1"/>
  <UnitDefinitions>
    <Unit name="rad"><BaseUnit rad="1"/></Unit>
    <Unit name="deg"><BaseUnit rad="1" factor="0.017453292519943295"/></Unit>
  </UnitDefinitions>
  <TypeDefinitions><SimpleType name="Angle"><Real unit="rad"/></SimpleType></TypeDefinitions>
  <DefaultExperiment startTime="0" stopTime="10" stepSize="0.1"/>
  <ModelVariables>
    <ScalarVariable name="k" valueReference="0" causality="parameter" variability="fixed"><Real start="2"/></ScalarVariable>
    <ScalarVariable name="u" valueReference="1" causality="input"><Real declaredType="Angle" start="0"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="2" causality="output" initial="calculated"><Real/></ScalarVariable>
    <ScalarVariable name="n" valueReference="0" causality="output" variability="discrete"><Integer/></ScalarVariable>
    <ScalarVariable name="b" valueReference="0" causality="parameter" variability="fixed"><Boolean start="true"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="3" dependencies="2"/><Unknown index="4" dependencies=""/></Outputs></ModelStructure>
</fmiModelDescription>"#;

    /// The "shipsim" tool's couplings are read; another tool's annotations (any content) and an
    /// FMU without annotations give none.
    #[test]
    fn parses_shipsim_couplings() {
        let annotated = XML.replace(
            "  <ModelVariables>",
            r#"  <VendorAnnotations>
    <Tool name="other"><Couplings><Coupling output="u" gain="k"/></Couplings><Anything x="1"/></Tool>
    <Tool name="shipsim"><Couplings><Coupling output="y" gain="k"/></Couplings></Tool>
  </VendorAnnotations>
  <ModelVariables>"#,
        );
        let md = ModelDescription::parse(&annotated).unwrap();
        assert_eq!(
            md.couplings(),
            [Coupling {
                output: "y".into(),
                gain: "k".into()
            }]
        );
        assert!(ModelDescription::parse(XML).unwrap().couplings().is_empty());
    }

    #[test]
    fn parses_typed_structure() {
        let md = ModelDescription::parse(XML).unwrap();
        assert_eq!(md.guid, "{abc}");
        let cs = md.co_simulation.as_ref().unwrap();
        assert!(cs.can_handle_variable_communication_step_size && cs.can_get_and_set_fmu_state);
        assert!(!cs.needs_execution_tool);
        let v = &md.model_variables.variables;
        assert_eq!(v.len(), 5);
        assert_eq!(v[0].causality, Causality::Parameter);
        assert_eq!(v[0].real.as_ref().unwrap().start, Some(2.0));
        assert_eq!(v[1].var_type(), Some(VarType::Real));
        assert_eq!(md.real_unit(&v[1]), Some("rad"));
        assert_eq!(v[3].var_type(), Some(VarType::Integer));
        assert_eq!(v[4].boolean.as_ref().unwrap().start, Some(true));
        assert!(md.output_depends_on(2, 1));
        assert!(!md.output_depends_on(3, 1));
        assert_eq!(md.unit("deg").unwrap().base_unit.unwrap().rad, 1);
        assert!(v[0].settable_in_instantiated());
        assert!(!v[2].settable_in_instantiated());
        assert!(v[1].settable_in_initialization_mode());
    }

    #[test]
    fn bad_xml_is_an_error() {
        assert!(ModelDescription::parse("<fmiModelDescription fmiVersion=").is_err());
        assert!(ModelDescription::parse("<fmiModelDescription/>").is_err());
    }
}
