/*
 * strata C ABI example: the contact law's two effects, yielding asperity tips (a
 * hardness) and the interface conductance, through
 * strata_law_new_with_law_options.
 *
 * Build (from the repository root, after `cargo build -p strata-capi`):
 *   cc examples/c/effects_example.c -I capi/include -L target/debug -lstrata_capi \
 *      -Wl,-rpath,$PWD/target/debug -lm -o effects_example
 *   ./effects_example tables/paper-two-layer.strata \
 *      tables/stacks/paper-two-layer-conducting.toml OUT_DIR
 *
 * 1. Capped tips: a polymer-like half-space (E = 4 GPa, nu = 0.15, hardness 0.2 GPa)
 *    under a rough surface, N and I model: the loading curve at its 8 samples, written
 *    as CSV to OUT_DIR/capped-MODEL.csv; a hardness of INFINITY is the elastic law.
 * 2. Conductance: the paper's two-layer stack with conductivities (a stack file, and
 *    the same stack from arrays with strata_stack_set_conductivities): h_c(g) and
 *    h_c(p) at the samples and between them, CSV to OUT_DIR/conductance-MODEL.csv;
 *    and the capped tips of section 1 conducting (both effects in one law), CSV to
 *    OUT_DIR/capped-conductance-MODEL.csv.
 * 3. Bad options: the error code and the message naming the field.
 * Numbers are printed with %.17g (exact round trip). capi/tests/c_example.rs runs this
 * file, compares the CSVs and numbers with `strata law` on the equivalent scenes, and
 * checks that the Fortran twin (examples/fortran/effects_example.f90) prints the same
 * lines bit for bit.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "strata.h"

#define SAMPLES 8

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

/* The law's sample separations: SAMPLES evenly spaced from first contact g0 down to
 * g_min, with the floating-point operations of the library's sampling. */
static void sample_gaps(const StrataLaw *law, double *gaps)
{
    double g0 = 0.0, gmin = 0.0;
    check(strata_law_first_contact_gap(law, &g0), "strata_law_first_contact_gap");
    check(strata_law_min_gap(law, &gmin), "strata_law_min_gap");
    for (int i = 0; i < SAMPLES; i++)
        gaps[i] = i + 1 == SAMPLES ? gmin : g0 - ((g0 - gmin) * (double)i) / (double)(SAMPLES - 1);
}

/* h_c(g), h_c(p(g)) and the combined eval at the samples and half-way between them. */
static void print_conductance(const char *label, const StrataLaw *law)
{
    double gaps[SAMPLES], at[2 * SAMPLES - 1];
    sample_gaps(law, gaps);
    for (int i = 0; i < SAMPLES; i++) {
        at[2 * i] = gaps[i];
        if (i + 1 < SAMPLES)
            at[2 * i + 1] = 0.5 * (gaps[i] + gaps[i + 1]);
    }
    double h[2 * SAMPLES - 1];
    check(strata_law_conductance_array(law, 2 * SAMPLES - 1, at, h),
          "strata_law_conductance_array");
    for (int i = 0; i < 2 * SAMPLES - 1; i++) {
        double p, a, d, hc, hg, hp;
        check(strata_law_eval_with_conductance(law, at[i], &p, &a, &d, &hc),
              "strata_law_eval_with_conductance");
        check(strata_law_conductance(law, at[i], &hg), "strata_law_conductance");
        check(strata_law_conductance_at_pressure(law, p, &hp),
              "strata_law_conductance_at_pressure");
        printf("conductance %s %.17g %.17g %.17g %.17g %.17g %.17g\n", label, at[i], p, hc,
               hg, h[i], hp);
    }
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: %s TABLE CONDUCTING_STACK OUT_DIR\n", argv[0]);
        return 2;
    }
    const char *table_path = argv[1], *stack_path = argv[2], *out_dir = argv[3];
    char path[4096];
    StrataTable *table = NULL;
    check(strata_table_load(table_path, &table), "strata_table_load");

    /* 1. Capped tips on a half-space (no table needed). */
    StrataStack *half = NULL;
    check(strata_stack_new(0, NULL, NULL, NULL, STRATA_BASE_ELASTIC, 4e9, 0.15, &half),
          "strata_stack_new");
    StrataSurface *rough = NULL;
    check(strata_surface_generate(1e-3, 128, 2.4, 2.0, 6.0, 3.4e-6, 5ULL, &rough),
          "strata_surface_generate");
    const int32_t models[2] = {STRATA_MODEL_INDEPENDENT, STRATA_MODEL_INTERACTING_PERIODIC};
    for (int m = 0; m < 2; m++) {
        StrataLawOptions o;
        check(strata_law_options_default(&o), "strata_law_options_default");
        o.hardness = 0.2e9;
        StrataLaw *capped = NULL, *inf = NULL, *elastic = NULL;
        check(strata_law_new_with_law_options(NULL, half, rough, models[m], 0.0, SAMPLES,
                                              NULL, &o, &capped),
              "strata_law_new_with_law_options (hardness)");
        double h = 0.0, gaps[SAMPLES];
        check(strata_law_hardness(capped, &h), "strata_law_hardness");
        printf("hardness %d %.17g\n", (int)models[m], h);
        snprintf(path, sizeof path, "%s/capped-%d.csv", out_dir, (int)models[m]);
        check(strata_law_write(capped, path, STRATA_FORMAT_CSV), "strata_law_write");
        sample_gaps(capped, gaps);
        for (int i = 0; i < SAMPLES; i++) {
            double p, a, d;
            check(strata_law_eval(capped, gaps[i], &p, &a, &d), "strata_law_eval");
            printf("capped %d %.17g %.17g %.17g\n", (int)models[m], gaps[i], p, a);
        }
        /* INFINITY: the elastic law, bit for bit */
        o.hardness = INFINITY;
        check(strata_law_new_with_law_options(NULL, half, rough, models[m], 0.0, SAMPLES,
                                              NULL, &o, &inf),
              "strata_law_new_with_law_options (INFINITY)");
        check(strata_law_new_from_stack(NULL, half, rough, models[m], 0.0, SAMPLES, NULL,
                                        &elastic),
              "strata_law_new_from_stack");
        check(strata_law_hardness(inf, &h), "strata_law_hardness");
        printf("hardness_infinity %d %.17g\n", (int)models[m], h);
        for (int i = 0; i + 1 < SAMPLES; i++) {
            for (int j = 0; j < 2; j++) {
                double g = j == 0 ? gaps[i] : 0.5 * (gaps[i] + gaps[i + 1]);
                double p1, a1, d1, p2, a2, d2;
                check(strata_law_eval(inf, g, &p1, &a1, &d1), "strata_law_eval");
                check(strata_law_eval(elastic, g, &p2, &a2, &d2), "strata_law_eval");
                printf("infinity_vs_elastic %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n",
                       (int)models[m], g, p1, p2, a1, a2, d1, d2);
            }
        }
        strata_law_free(elastic);
        strata_law_free(inf);
        strata_law_free(capped);
    }

    /* 2. Conductance on the paper's stack with conductivities (stack file). */
    StrataStack *conducting = NULL;
    check(strata_stack_load(stack_path, &conducting), "strata_stack_load");
    StrataSurface *paper = NULL;
    check(strata_surface_generate(1e-3, 128, 2.4, 2.0, 10.0, 3.4e-6, 20240611ULL, &paper),
          "strata_surface_generate");
    StrataLawOptions th;
    check(strata_law_options_default(&th), "strata_law_options_default");
    th.conductance_kind = STRATA_CONDUCTANCE_THERMAL;
    th.counterface_conduction = STRATA_COUNTERFACE_CONDUCTION_HALF_SPACE;
    th.counterface_conductivity = 50.0; /* a steel flat, W/(m K) */
    StrataLaw *li = NULL;
    check(strata_law_new_with_law_options(table, conducting, paper,
                                          STRATA_MODEL_INTERACTING_PERIODIC, 2e-6, SAMPLES,
                                          NULL, &th, &li),
          "strata_law_new_with_law_options (thermal, I model)");
    int32_t kind = -1;
    check(strata_law_conductance_kind(li, &kind), "strata_law_conductance_kind");
    printf("conductance_kind thermal %d\n", (int)kind);
    snprintf(path, sizeof path, "%s/conductance-%d.csv", out_dir,
             (int)STRATA_MODEL_INTERACTING_PERIODIC);
    check(strata_law_write(li, path, STRATA_FORMAT_CSV), "strata_law_write");
    print_conductance("thermal_i", li);

    StrataLawOptions el;
    check(strata_law_options_default(&el), "strata_law_options_default");
    el.conductance_kind = STRATA_CONDUCTANCE_ELECTRICAL;
    el.counterface_conduction = STRATA_COUNTERFACE_CONDUCTION_PERFECT;
    StrataLaw *ln = NULL;
    check(strata_law_new_with_law_options(table, conducting, paper, STRATA_MODEL_INDEPENDENT,
                                          2e-6, SAMPLES, NULL, &el, &ln),
          "strata_law_new_with_law_options (electrical, N model)");
    check(strata_law_conductance_kind(ln, &kind), "strata_law_conductance_kind");
    printf("conductance_kind electrical %d\n", (int)kind);
    snprintf(path, sizeof path, "%s/conductance-%d.csv", out_dir, (int)STRATA_MODEL_INDEPENDENT);
    check(strata_law_write(ln, path, STRATA_FORMAT_CSV), "strata_law_write");
    print_conductance("electrical_n", ln);

    /* The same stack from arrays: thermal conductivities 0.5 and 5 W/(m K) on an
     * isothermal base (tables/stacks/paper-two-layer-conducting.toml). */
    const double thickness[2] = {100e-6, 900e-6}, young[2] = {4e9, 20e9},
                 poisson[2] = {0.15, 0.15}, k[2] = {0.5, 5.0};
    StrataStack *memory = NULL;
    check(strata_stack_new(2, thickness, young, poisson, STRATA_BASE_RIGID, 0.0, 0.0, &memory),
          "strata_stack_new");
    check(strata_stack_set_conductivities(memory, STRATA_CONDUCTANCE_THERMAL, 2, k,
                                          STRATA_BASE_CONDUCTION_ISOTHERMAL, 0.0),
          "strata_stack_set_conductivities");
    StrataLaw *from_memory = NULL, *from_file = NULL;
    check(strata_law_new_with_law_options(table, memory, paper, STRATA_MODEL_INDEPENDENT, 2e-6,
                                          SAMPLES, NULL, &th, &from_memory),
          "strata_law_new_with_law_options (memory stack)");
    check(strata_law_new_with_law_options(table, conducting, paper, STRATA_MODEL_INDEPENDENT,
                                          2e-6, SAMPLES, NULL, &th, &from_file),
          "strata_law_new_with_law_options (file stack)");
    {
        double gaps[SAMPLES];
        sample_gaps(from_file, gaps);
        for (int i = 0; i < SAMPLES; i++) {
            double h1, h2;
            check(strata_law_conductance(from_memory, gaps[i], &h1), "strata_law_conductance");
            check(strata_law_conductance(from_file, gaps[i], &h2), "strata_law_conductance");
            printf("memory_vs_file %.17g %.17g %.17g\n", gaps[i], h1, h2);
        }
    }

    /* Capped tips that conduct: the half-space of section 1 with a thermal conductivity of
     * 0.5 W/(m K), hardness 0.2 GPa, against the steel flat: h_c of the capped spots. */
    StrataStack *half_k = NULL;
    check(strata_stack_new(0, NULL, NULL, NULL, STRATA_BASE_ELASTIC, 4e9, 0.15, &half_k),
          "strata_stack_new");
    check(strata_stack_set_conductivities(half_k, STRATA_CONDUCTANCE_THERMAL, 0, NULL,
                                          STRATA_BASE_CONDUCTION_HALF_SPACE, 0.5),
          "strata_stack_set_conductivities");
    for (int m = 0; m < 2; m++) {
        StrataLawOptions ct = th; /* thermal, the steel flat */
        ct.hardness = 0.2e9;
        StrataLaw *cc = NULL;
        check(strata_law_new_with_law_options(NULL, half_k, rough, models[m], 0.0, SAMPLES,
                                              NULL, &ct, &cc),
              "strata_law_new_with_law_options (hardness, thermal)");
        snprintf(path, sizeof path, "%s/capped-conductance-%d.csv", out_dir, (int)models[m]);
        check(strata_law_write(cc, path, STRATA_FORMAT_CSV), "strata_law_write");
        print_conductance(m == 0 ? "capped_n" : "capped_i", cc);
        strata_law_free(cc);
    }
    strata_stack_free(half_k);

    /* 3. Bad options come back as codes with a message naming the field. */
    StrataLaw *other = NULL;
    StrataLawOptions bad;
    double v = 0.0, gmin = 0.0;
    check(strata_law_min_gap(li, &gmin), "strata_law_min_gap");
    check(strata_law_options_default(&bad), "strata_law_options_default");
    bad.hardness = -1.0;
    expect_error("negative_hardness",
                 strata_law_new_with_law_options(NULL, half, rough, STRATA_MODEL_INDEPENDENT,
                                                 0.0, SAMPLES, NULL, &bad, &other));
    check(strata_law_options_default(&bad), "strata_law_options_default");
    bad.conductance_kind = 7;
    expect_error("unknown_kind",
                 strata_law_new_with_law_options(NULL, half, rough, STRATA_MODEL_INDEPENDENT,
                                                 0.0, SAMPLES, NULL, &bad, &other));
    check(strata_law_options_default(&bad), "strata_law_options_default");
    bad.conductance_kind = STRATA_CONDUCTANCE_THERMAL;
    bad.counterface_conduction = STRATA_COUNTERFACE_CONDUCTION_PERFECT;
    expect_error("missing_conductivity",
                 strata_law_new_with_law_options(NULL, half, rough, STRATA_MODEL_INDEPENDENT,
                                                 0.0, SAMPLES, NULL, &bad, &other));
    bad.counterface_conduction = STRATA_COUNTERFACE_CONDUCTION_STACK;
    expect_error("rigid_flat_conduction_unset",
                 strata_law_new_with_law_options(table, conducting, paper,
                                                 STRATA_MODEL_INDEPENDENT, 2e-6, SAMPLES, NULL,
                                                 &bad, &other));
    bad.counterface_conduction = STRATA_COUNTERFACE_CONDUCTION_HALF_SPACE;
    bad.counterface_conductivity = -50.0;
    expect_error("negative_counterface_conductivity",
                 strata_law_new_with_law_options(table, conducting, paper,
                                                 STRATA_MODEL_INDEPENDENT, 2e-6, SAMPLES, NULL,
                                                 &bad, &other));
    check(strata_law_options_default(&bad), "strata_law_options_default");
    bad.size = 0;
    expect_error("options_not_initialised",
                 strata_law_new_with_law_options(NULL, half, rough, STRATA_MODEL_INDEPENDENT,
                                                 0.0, SAMPLES, NULL, &bad, &other));
    const double bad_k[2] = {0.5, -1.0};
    expect_error("negative_layer_conductivity",
                 strata_stack_set_conductivities(memory, STRATA_CONDUCTANCE_THERMAL, 2, bad_k,
                                                 STRATA_BASE_CONDUCTION_ISOTHERMAL, 0.0));
    expect_error("wrong_layer_count",
                 strata_stack_set_conductivities(memory, STRATA_CONDUCTANCE_THERMAL, 1, k,
                                                 STRATA_BASE_CONDUCTION_ISOTHERMAL, 0.0));
    expect_error("conductance_below_range", strata_law_conductance(li, gmin - 1e-7, &v));
    {
        StrataLaw *plain = NULL;
        check(strata_law_new_from_stack(table, conducting, paper, STRATA_MODEL_INDEPENDENT,
                                        2e-6, SAMPLES, NULL, &plain),
              "strata_law_new_from_stack");
        expect_error("no_conductance_in_law", strata_law_conductance(plain, gmin, &v));
        strata_law_free(plain);
    }
    expect_error("pressure_above_samples", strata_law_conductance_at_pressure(li, 1e12, &v));

    strata_law_free(from_file);
    strata_law_free(from_memory);
    strata_law_free(ln);
    strata_law_free(li);
    strata_stack_free(memory);
    strata_stack_free(conducting);
    strata_stack_free(half);
    strata_surface_free(paper);
    strata_surface_free(rough);
    strata_table_free(table);
    return 0;
}
