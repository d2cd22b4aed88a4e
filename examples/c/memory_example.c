/*
 * strata C ABI from memory: a stack from arrays, a surface from a height buffer, and
 * p, A/A0 and dp/dg in one call (scalar and array) - no stack or surface file.
 *
 * Build (from the repository root, after `cargo build -p strata-capi`):
 *   cc examples/c/memory_example.c -I capi/include -L target/debug -lstrata_capi \
 *      -Wl,-rpath,$PWD/target/debug -o memory_example
 *   ./memory_example TABLE STACK.toml HEIGHTS.bin N L
 * with the paper's table and two-layer stack (tables/paper-two-layer.strata,
 * tables/stacks/paper-two-layer-E2E1-1.toml), HEIGHTS.bin N*N little-endian doubles
 * (m, x the first index) of a periodic square of side L (m).
 *
 * Builds the law twice on the same heights: from the stack file (strata_law_new) and
 * from the same stack given as arrays (strata_stack_new + strata_law_new_from_stack),
 * and prints at 12 separations the three single queries of the first ("point"), the
 * combined query of the second ("memory") and its array query ("array"), %.17g (exact
 * round trip); then the errors of bad input. capi/tests/c_example.rs checks that all
 * three agree bit for bit, and with the Rust API; its Fortran twin,
 * examples/fortran/memory_example.f90, must print the same lines.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <math.h>

#include "strata.h"

static void check(int32_t code, const char *what)
{
    if (code != STRATA_OK) {
        fprintf(stderr, "%s failed (code %d): %s\n", what, (int)code,
                strata_last_error_message());
        exit(1);
    }
}

static void expect_error(const char *name, int32_t code)
{
    printf("error %s %d %s\n", name, (int)code,
           code == STRATA_OK ? "(no error)" : strata_last_error_message());
}

int main(int argc, char **argv)
{
    if (argc < 6) {
        fprintf(stderr, "usage: memory_example TABLE STACK.toml HEIGHTS.bin N L\n");
        return 2;
    }
    const char *table_path = argv[1];
    const char *stack_path = argv[2];
    const char *heights_path = argv[3];
    size_t n = (size_t)atol(argv[4]);
    double size = atof(argv[5]);
    const int32_t model = STRATA_MODEL_INTERACTING_PERIODIC;

    printf("version %d %d %d %s\n", STRATA_VERSION_MAJOR, STRATA_VERSION_MINOR,
           STRATA_VERSION_PATCH, strata_version());

    /* The heights: N*N doubles, x the first (slow) index. */
    double *heights = malloc(n * n * sizeof(double));
    FILE *f = fopen(heights_path, "rb");
    if (heights == NULL || f == NULL || fread(heights, sizeof(double), n * n, f) != n * n) {
        fprintf(stderr, "cannot read %zu heights from %s\n", n * n, heights_path);
        return 1;
    }
    fclose(f);

    StrataTable *table = NULL;
    StrataSurface *surface = NULL;
    StrataStack *stack = NULL;
    StrataLaw *from_file = NULL, *from_memory = NULL;
    check(strata_table_load(table_path, &table), "strata_table_load");
    double dx = size / (double)n;
    check(strata_surface_new(heights, n, n, dx, dx, 1, &surface), "strata_surface_new");
    /* The stack file's values: 100 um of E = 4 GPa on 900 um of E = 4 GPa, rigid base. */
    const double thickness[2] = {100e-6, 900e-6};
    const double young[2] = {4e9, 4e9};
    const double poisson[2] = {0.15, 0.15};
    check(strata_stack_new(2, thickness, young, poisson, STRATA_BASE_RIGID, 0.0, 0.0, &stack),
          "strata_stack_new");
    check(strata_law_new(table, stack_path, surface, model, 1e-6, 50, &from_file),
          "strata_law_new");
    check(strata_law_new_from_stack(table, stack, surface, model, 1e-6, 50, NULL, &from_memory),
          "strata_law_new_from_stack");

    double g0 = 0.0, gmin = 0.0;
    check(strata_law_first_contact_gap(from_memory, &g0), "strata_law_first_contact_gap");
    check(strata_law_min_gap(from_memory, &gmin), "strata_law_min_gap");
    double gaps[12];
    int k = 0;
    gaps[k++] = g0 + 1e-7;
    gaps[k++] = g0;
    for (int i = 1; i <= 9; i++)
        gaps[k++] = g0 - (g0 - gmin) * (i - 0.3) / 9.0;
    gaps[k++] = gmin;

    double ap[12], aa[12], ad[12];
    check(strata_law_eval_array(from_memory, 12, gaps, ap, aa, ad), "strata_law_eval_array");
    for (int i = 0; i < 12; i++) {
        double p, a, d;
        check(strata_law_pressure(from_file, gaps[i], &p), "strata_law_pressure");
        check(strata_law_area_fraction(from_file, gaps[i], &a), "strata_law_area_fraction");
        check(strata_law_dp_dg(from_file, gaps[i], &d), "strata_law_dp_dg");
        printf("point %.17g %.17g %.17g %.17g\n", gaps[i], p, a, d);
        check(strata_law_eval(from_memory, gaps[i], &p, &a, &d), "strata_law_eval");
        printf("memory %.17g %.17g %.17g %.17g\n", gaps[i], p, a, d);
        printf("array %.17g %.17g %.17g %.17g\n", gaps[i], ap[i], aa[i], ad[i]);
    }

    /* Bad input: a code and a message naming the argument; nothing aborts. */
    StrataStack *bad = NULL;
    const double negative[2] = {4e9, -1.0};
    const double not_finite[2] = {NAN, 900e-6};
    expect_error("stack_negative_young",
                 strata_stack_new(2, thickness, negative, poisson, STRATA_BASE_RIGID, 0, 0, &bad));
    expect_error("stack_nan_thickness",
                 strata_stack_new(2, not_finite, young, poisson, STRATA_BASE_RIGID, 0, 0, &bad));
    expect_error("stack_null_young",
                 strata_stack_new(2, thickness, NULL, poisson, STRATA_BASE_RIGID, 0, 0, &bad));
    expect_error("stack_bad_base_kind",
                 strata_stack_new(2, thickness, young, poisson, 5, 0, 0, &bad));
    expect_error("stack_rigid_without_layers",
                 strata_stack_new(0, NULL, NULL, NULL, STRATA_BASE_RIGID, 0, 0, &bad));
    expect_error("stack_bad_base_poisson",
                 strata_stack_new(0, NULL, NULL, NULL, STRATA_BASE_ELASTIC, 4e9, 0.7, &bad));
    StrataSurface *other_surface = NULL;
    expect_error("surface_null_heights",
                 strata_surface_new(NULL, n, n, dx, dx, 1, &other_surface));
    expect_error("surface_zero_dx", strata_surface_new(heights, n, n, 0.0, dx, 1, &other_surface));
    expect_error("surface_too_small", strata_surface_new(heights, 2, 2, dx, dx, 1, &other_surface));
    double kept = heights[5];
    heights[5] = NAN;
    expect_error("surface_nan_height",
                 strata_surface_new(heights, n, n, dx, dx, 1, &other_surface));
    heights[5] = kept;
    StrataLaw *other = NULL;
    expect_error("law_null_stack",
                 strata_law_new_from_stack(table, NULL, surface, model, 1e-6, 50, NULL, &other));
    double p, a, d;
    expect_error("eval_null_area", strata_law_eval(from_memory, gmin, &p, NULL, &d));
    expect_error("eval_below_range", strata_law_eval(from_memory, gmin - 1e-7, &p, &a, &d));
    /* All or nothing: one gap out of range leaves the outputs as they were. */
    double bad_gaps[3] = {g0, gmin - 1e-7, gmin};
    double op[3] = {-1, -1, -1}, oa[3] = {-1, -1, -1}, od[3] = {-1, -1, -1};
    expect_error("eval_array_below_range",
                 strata_law_eval_array(from_memory, 3, bad_gaps, op, oa, od));
    printf("untouched %d\n", op[0] == -1 && oa[0] == -1 && od[2] == -1);
    expect_error("eval_array_null_gaps", strata_law_eval_array(from_memory, 3, NULL, op, oa, od));
    expect_error("eval_array_empty", strata_law_eval_array(from_memory, 0, NULL, NULL, NULL, NULL));

    strata_law_free(from_memory);
    strata_law_free(from_file);
    strata_stack_free(stack);
    strata_surface_free(surface);
    strata_table_free(table);
    free(heights);
    return 0;
}
