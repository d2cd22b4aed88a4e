/*
 * strata C ABI example: the contact law of the paper's rough surface on the
 * two-layer stack E2/E1 = 1, interacting asperities (I model, periodic images).
 *
 * Build (from the repository root, after `cargo build -p strata-capi`):
 *   cc examples/c/law_example.c -I capi/include -L target/debug -lstrata_capi \
 *      -Wl,-rpath,$PWD/target/debug -o law_example
 *   ./law_example tables/paper-two-layer.strata tables/stacks/paper-two-layer-E2E1-1.toml
 *
 * Prints p(g) (Pa), A(g)/A0 and dp/dg (Pa/m) at a few separations g (m) with %.17g
 * (exact round trip), then shows how errors are reported. SI units.
 * capi/tests/c_example.rs builds and runs this file and checks every number bit for
 * bit against the Rust API; its Fortran twin, examples/fortran/law_example.f90, must
 * print the same numbers bit for bit.
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

/* Prints the code and message of a call expected to fail. */
static void expect_error(const char *name, int32_t code)
{
    printf("error %s %d %s\n", name, (int)code,
           code == STRATA_OK ? "(no error)" : strata_last_error_message());
}

int main(int argc, char **argv)
{
    const char *table_path = argc > 1 ? argv[1] : "tables/paper-two-layer.strata";
    const char *stack_path =
        argc > 2 ? argv[2] : "tables/stacks/paper-two-layer-E2E1-1.toml";
    int32_t model = argc > 3 ? (int32_t)atoi(argv[3]) : STRATA_MODEL_INTERACTING_PERIODIC;

    StrataTable *table = NULL;
    StrataSurface *surface = NULL;
    StrataLaw *law = NULL;

    printf("strata %s\n", strata_version());
    check(strata_table_load(table_path, &table), "strata_table_load");
    /* The paper's surface (scenes/paper-E2E1-1-*.toml): L = 1 mm, 512 x 512,
     * D_f = 2.4, k = 2..10, RMS 3.4 um, seed 20240611. */
    check(strata_surface_generate(1e-3, 512, 2.4, 2.0, 10.0, 3.4e-6, 20240611ULL, &surface),
          "strata_surface_generate");
    /* 200 samples from first contact down to g = 1 um. */
    check(strata_law_new(table, stack_path, surface, model, 1e-6, 200, &law),
          "strata_law_new");

    double g0 = 0.0, gmin = 0.0;
    check(strata_law_first_contact_gap(law, &g0), "strata_law_first_contact_gap");
    check(strata_law_min_gap(law, &gmin), "strata_law_min_gap");
    printf("first_contact_gap %.17g\n", g0);
    printf("min_gap %.17g\n", gmin);

    /* Above first contact, at it, inside (not on the samples), at the bottom. */
    double gaps[12];
    int n = 0;
    gaps[n++] = g0 + 1e-7;
    gaps[n++] = g0;
    for (int k = 1; k <= 9; k++)
        gaps[n++] = g0 - (g0 - gmin) * (k - 0.3) / 9.0;
    gaps[n++] = gmin;

    printf("# gap pressure area_fraction dp_dg\n");
    for (int i = 0; i < n; i++) {
        double p, a, d;
        check(strata_law_pressure(law, gaps[i], &p), "strata_law_pressure");
        check(strata_law_area_fraction(law, gaps[i], &a), "strata_law_area_fraction");
        check(strata_law_dp_dg(law, gaps[i], &d), "strata_law_dp_dg");
        printf("point %.17g %.17g %.17g %.17g\n", gaps[i], p, a, d);
    }

    /* Errors come back as codes with a message; nothing aborts. */
    double v;
    expect_error("nan_gap", strata_law_pressure(law, NAN, &v));
    expect_error("below_range", strata_law_pressure(law, gmin - 1e-7, &v));
    expect_error("null_out", strata_law_dp_dg(law, gmin, NULL));
    expect_error("null_law", strata_law_area_fraction(NULL, gmin, &v));
    StrataTable *missing = NULL;
    expect_error("missing_table", strata_table_load("no/such/table.strata", &missing));
    StrataLaw *other = NULL;
    expect_error("layered_without_table",
                 strata_law_new(NULL, stack_path, surface, model, 1e-6, 200, &other));
    expect_error("bad_model", strata_law_new(table, stack_path, surface, 7, 1e-6, 200, &other));
    expect_error("min_gap_above_contact",
                 strata_law_new(table, stack_path, surface, model, g0 + 1e-6, 200, &other));
    /* Absurd sizes are refused before anything is allocated (cap STRATA_MAX_SAMPLES). */
    expect_error("samples_1e9",
                 strata_law_new(table, stack_path, surface, model, 1e-6, 1000000000, &other));
    expect_error("samples_size_max",
                 strata_law_new(table, stack_path, surface, model, 1e-6, SIZE_MAX, &other));

    strata_law_free(law);
    strata_surface_free(surface);
    strata_table_free(table);
    return 0;
}
