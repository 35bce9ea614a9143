//! Runs of variables that several FMUs declare alike, written once. Use one in place of an
//! entry of a variable table: `pose!(out());` splices its entries in at that position, so the
//! value references of the entries before and after it are those of the full table (a fragment
//! never renumbers anything). The argument is the access path, from the model, of a value that
//! has the fragment's fields.

/// Heading (continuous and wrapped) and the north/east position of a hull, in that order, from
/// a value with fields `heading`, `heading_wrapped`, `x` and `y` (e.g. `pose!(out());` reads
/// `m.out().heading`, ...).
#[macro_export]
macro_rules! pose {
    (@fragment [$model:ty] [$($done:tt)*] ($($path:tt)*) $($rest:tt)*) => {
        $crate::__variables!(@[$model] [$($done)*]
            heading!($($path)*);
            output real "x" ["m"] (|m| m.$($path)*.x), "North position";
            output real "y" ["m"] (|m| m.$($path)*.y), "East position";
            $($rest)*
        )
    };
}

/// Heading psi, continuous and wrapped, from a value with fields `heading` and
/// `heading_wrapped`.
#[macro_export]
macro_rules! heading {
    (@fragment [$model:ty] [$($done:tt)*] ($($path:tt)*) $($rest:tt)*) => {
        $crate::__variables!(@[$model] [$($done)*]
            output real "heading" ["rad"] (|m| m.$($path)*.heading),
                "Heading psi from north, clockwise, continuous (not wrapped)";
            output real "heading_wrapped" ["rad"] (|m| m.$($path)*.heading_wrapped),
                "Heading wrapped to (-pi, pi]";
            $($rest)*
        )
    };
}
