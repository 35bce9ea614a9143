//! The `causality`, `variability` and `initial` attributes of a ScalarVariable (FMI 2.0
//! section 2.2.7), shared by the export layer (which writes them) and the importer (which reads
//! them). With the `serde` feature they deserialize from their XML spelling.

/// Defines an attribute enum with its XML spelling; `Default` is the standard's default.
macro_rules! attribute {
    ($(#[$doc:meta])* $enum:ident { $($variant:ident = $xml:literal $(@$default:ident)?,)* }) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[cfg_attr(feature = "serde", derive(serde::Deserialize))]
        pub enum $enum {
            $(#[cfg_attr(feature = "serde", serde(rename = $xml))] $variant,)*
        }
        impl $enum {
            /// The attribute's spelling in `modelDescription.xml`.
            pub const fn xml_name(self) -> &'static str {
                match self {
                    $($enum::$variant => $xml,)*
                }
            }
        }
        impl ::std::fmt::Display for $enum {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.xml_name())
            }
        }
        $(attribute!(@default $enum $variant $($default)?);)*
    };
    (@default $enum:ident $variant:ident default) => {
        impl Default for $enum {
            fn default() -> Self {
                $enum::$variant
            }
        }
    };
    (@default $enum:ident $variant:ident) => {};
}

attribute! {
    /// `causality` (FMI 2.0 section 2.2.7); the default is `local`.
    Causality {
        Parameter = "parameter",
        CalculatedParameter = "calculatedParameter",
        Input = "input",
        Output = "output",
        Local = "local" @default,
        Independent = "independent",
    }
}

attribute! {
    /// `variability` (FMI 2.0 section 2.2.7); the default is `continuous`.
    Variability {
        Constant = "constant",
        Fixed = "fixed",
        Tunable = "tunable",
        Discrete = "discrete",
        Continuous = "continuous" @default,
    }
}

attribute! {
    /// `initial` (FMI 2.0 section 2.2.7); its default depends on causality and variability.
    Initial {
        Exact = "exact",
        Approx = "approx",
        Calculated = "calculated",
    }
}
