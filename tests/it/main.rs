//! Integration tests of the strata workspace, one binary (one link) for all of them.
//! Each module is one concern; `support` holds the shared paths and helpers.

mod support;
mod tools;

mod asperity;
mod asperity_vs_bem;
mod bem_free;
mod bem_paths;
mod bem_reference;
mod calculix;
mod compare;
mod compliance_cli;
mod compliance_hard_cases;
mod compliance_second_method;
mod conductance;
mod counterface;
mod docs;
mod errors;
mod field_inputs;
mod fuzz_solvers;
mod hard_cases;
mod law;
mod limits;
mod maps;
mod measured_law;
mod module_cycles;
mod outputs;
mod plastic;
mod progress;
mod rectangular;
mod rough_reference;
mod runtime_deps;
mod scale;
mod scene_fuzz;
mod soft_stacks;
mod solve;
mod solve_bem;
mod stack_fuzz;
mod stalls;
mod stdio;
mod study;
mod sweep;
mod table_fuzz;
mod tables;
mod x3p;
mod zero_mean_images;
