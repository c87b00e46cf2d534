/* The C ABI from C: models, homogenize against a closed form, the curve, the generators, the
 * solver layer on a small system with a known solution, the stateful cell, and errors as
 * statuses with messages.
 * Build and run from the repository root (see .ci/run):
 *   cargo build --release -p fibercell-c
 *   gcc -std=c11 -Wall -Wextra -Werror -I bindings/c/include bindings/c/tests/c/test_fibercell.c \
 *       target/release/libfibercell_c.a -lm -lpthread -ldl -o target/c_test && target/c_test
 * Prints one line `test result: ok. N passed; M failed` and exits non-zero on a failure. */
#include "fibercell.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int passed = 0, failed = 0;

#define CHECK(cond, ...)                                                                     \
    do {                                                                                     \
        if (cond) {                                                                          \
            passed++;                                                                        \
        } else {                                                                             \
            failed++;                                                                        \
            fprintf(stderr, "FAILED %s:%d: %s: ", __FILE__, __LINE__, #cond);                \
            fprintf(stderr, __VA_ARGS__);                                                    \
            fprintf(stderr, " (last error: %s)\n", fc_last_error());                         \
        }                                                                                    \
    } while (0)

/* A11 = E A / Ly of the grid cell (E = 1 GPa, r = 0.2 mm, Ly = 7 mm: its file's comment). */
static void homogenize_matches_the_closed_form(void) {
    FcModel *cell = NULL;
    CHECK(fc_model_load("fixtures/ok_cell_grid.toml", &cell) == FC_OK, "load");
    size_t nodes = 0, fibers = 0, elements = 0;
    bool is_cell = false;
    CHECK(fc_model_size(cell, &nodes, &fibers, &elements, &is_cell) == FC_OK, "size");
    CHECK(is_cell && fibers == 2 && elements == 8, "%zu fibers, %zu elements", fibers, elements);
    double abd[36];
    char *json = NULL;
    FcSolveOptions lu = {"faer-lu", NULL};
    CHECK(fc_homogenize(cell, NULL, abd, &json) == FC_OK, "homogenize");
    double a11 = 1e9 * M_PI * 2e-4 * 2e-4 / 7e-3;
    CHECK(fabs(abd[0] / a11 - 1.0) <= 1e-9, "A11 %.17g against %.17g", abd[0], a11);
    CHECK(json != NULL && strstr(json, "\"abd\"") != NULL, "the JSON document");
    fc_string_free(json);
    double abd_lu[36];
    CHECK(fc_homogenize(cell, &lu, abd_lu, NULL) == FC_OK, "homogenize with faer-lu");
    CHECK(fabs(abd_lu[0] / abd[0] - 1.0) <= 1e-9, "LU %.17g", abd_lu[0]);
    fc_model_free(cell);
}

static void curve_and_generators_run(void) {
    FcModel *cell = NULL;
    CHECK(fc_model_load("fixtures/ok_cell_contact.toml", &cell) == FC_OK, "load");
    char *json = NULL;
    CHECK(fc_curve(cell, "e11=0.002", 5, false, NULL, &json) == FC_OK, "curve");
    CHECK(json != NULL && strstr(json, "\"points\"") != NULL, "its document");
    fc_string_free(json);
    fc_model_free(cell);
    FcModel *knit = NULL;
    CHECK(fc_generate("{\"family\": \"knitted\", \"wales\": 2, \"courses\": 2}", &knit) == FC_OK,
          "generate");
    bool is_cell = false;
    CHECK(fc_model_size(knit, NULL, NULL, NULL, &is_cell) == FC_OK && is_cell, "a cell");
    char *text = NULL;
    CHECK(fc_model_to_json(knit, &text) == FC_OK && strstr(text, "\"fibers\"") != NULL, "json");
    FcModel *back = NULL;
    CHECK(fc_model_from_string(text, "json", &back) == FC_OK, "read back");
    fc_string_free(text);
    fc_model_free(back);
    fc_model_free(knit);
}

/* A = [[4,1,0],[1,3,1],[0,1,2]] (both triangles), b = A (1,2,3): x = (1,2,3). */
static void the_solver_layer_solves_a_known_system(void) {
    const size_t col_ptr[] = {0, 2, 5, 7};
    const size_t row_idx[] = {0, 1, 0, 1, 2, 1, 2};
    const double values[] = {4, 1, 1, 3, 1, 1, 2};
    const double b[] = {6, 10, 8};
    const char *backends[] = {"faer-cholesky", "faer-lu", "cg"};
    for (int k = 0; k < 3; k++) {
        FcSolveOptions o = {backends[k], "amd"};
        FcSolver *s = NULL;
        CHECK(fc_solver_new(&o, &s) == FC_OK, "%s", backends[k]);
        CHECK(fc_solver_factorize(s, 3, col_ptr, row_idx, values) == FC_OK, "%s", backends[k]);
        double x[3], e = 1.0;
        CHECK(fc_solver_solve(s, b, x, &e) == FC_OK, "%s", backends[k]);
        for (int i = 0; i < 3; i++) {
            CHECK(fabs(x[i] - (i + 1)) <= 1e-12, "%s x[%d] = %.17g", backends[k], i, x[i]);
        }
        CHECK(e <= 1e-14, "%s backward error %g", backends[k], e);
        fc_solver_free(s);
    }
}

/* The stateful cell on the grid cell (no contacts: linear): N11 = A11 ε11 and dN11/dε11 = A11,
 * A11 = E A / Ly, solved on the cell's factorization at rest; a trial commits nothing; a copy
 * continues like the original; a state of another cell and a NaN increment are refused, leaving
 * the state as it was. */
static void the_stateful_cell_updates_and_tries(void) {
    FcModel *grid = NULL;
    CHECK(fc_model_load("fixtures/ok_cell_grid.toml", &grid) == FC_OK, "load");
    FcCell *cell = NULL, *other = NULL;
    CHECK(fc_cell_new(grid, NULL, true, &cell) == FC_OK, "cell");
    CHECK(fc_cell_new(grid, NULL, false, &other) == FC_OK, "another cell");
    FcCellState *state = NULL, *foreign = NULL, *copy = NULL;
    CHECK(fc_cell_state_new(cell, &state) == FC_OK, "state");
    CHECK(fc_cell_state_new(other, &foreign) == FC_OK, "a state of the other cell");
    double a11 = 1e9 * M_PI * 2e-4 * 2e-4 / 7e-3;
    const double de[6] = {1e-3, 0, 0, 0, 0, 0};
    FcCellResponse r;
    for (int k = 1; k <= 2; k++) {
        CHECK(fc_cell_update(cell, state, de, &r) == FC_OK, "update %d", k);
        CHECK(fabs(r.resultant[0] / (a11 * k * 1e-3) - 1.0) <= 1e-9, "N11 %.17g", r.resultant[0]);
        /* Both on the cell's factorization at rest, none of the state's own. */
        CHECK(r.factorizations == 0, "update %d factorized %zu times", k, (size_t)r.factorizations);
    }
    CHECK(r.has_tangent && fabs(r.tangent[0] / a11 - 1.0) <= 1e-9, "dN11/de11 %.17g",
          r.tangent[0]);
    CHECK(r.slip == 0 && r.dissipated == 0.0, "no contact, no dissipation");
    FcCellResponse t;
    CHECK(fc_cell_trial(cell, state, de, &t) == FC_OK, "trial");
    double strain[6];
    CHECK(fc_cell_state_strain(state, strain) == FC_OK && strain[0] == 2e-3, "committed %g",
          strain[0]);
    CHECK(fc_cell_state_clone(state, &copy) == FC_OK, "clone");
    CHECK(fc_cell_state_release_caches(copy) == FC_OK, "release the copy's caches");
    FcCellResponse a, b;
    CHECK(fc_cell_update(cell, state, de, &a) == FC_OK && fc_cell_update(cell, copy, de, &b) == FC_OK,
          "both update");
    CHECK(fabs(a.resultant[0] / t.resultant[0] - 1.0) <= 1e-12 &&
              fabs(b.resultant[0] / a.resultant[0] - 1.0) <= 1e-12,
          "trial %.17g, update %.17g, copy %.17g", t.resultant[0], a.resultant[0], b.resultant[0]);
    CHECK(fc_cell_update(cell, foreign, de, &r) == FC_INVALID_ARGUMENT &&
              strstr(fc_last_error(), "another cell") != NULL,
          "foreign state: %s", fc_last_error());
    const double nan_step[6] = {NAN, 0, 0, 0, 0, 0};
    CHECK(fc_cell_update(cell, state, nan_step, &r) == FC_ERROR &&
              strstr(fc_last_error(), "not finite") != NULL,
          "NaN: %s", fc_last_error());
    CHECK(fc_cell_state_strain(state, strain) == FC_OK && strain[0] == 3e-3, "unchanged %g",
          strain[0]);
    fc_cell_state_free(copy);
    fc_cell_state_free(foreign);
    fc_cell_state_free(state);
    fc_cell_free(other);
    fc_cell_free(cell);
    fc_cell_free(NULL);
    fc_cell_state_free(NULL);
    fc_model_free(grid);
}

static void errors_are_statuses_with_messages(void) {
    FcModel *m = NULL;
    CHECK(fc_model_from_string("nodes = [", "toml", &m) == FC_ERROR && m == NULL, "bad TOML");
    CHECK(strstr(fc_last_error(), "<toml string>:1:") != NULL, "names the line: %s",
          fc_last_error());
    CHECK(fc_model_load(NULL, &m) == FC_INVALID_ARGUMENT, "NULL path");
    CHECK(fc_model_load("no/such/file.toml", &m) == FC_ERROR, "missing file");
    CHECK(fc_model_from_string("", "yaml", &m) == FC_INVALID_ARGUMENT, "unknown format");
    CHECK(fc_generate("{\"family\": \"crochet\"}", &m) == FC_ERROR, "unknown family");
    FcModel *frame = NULL;
    CHECK(fc_model_load("fixtures/ok_frame3d.toml", &frame) == FC_OK, "frame");
    double abd[36];
    CHECK(fc_homogenize(frame, NULL, abd, NULL) == FC_ERROR, "homogenize needs a cell");
    FcSolveOptions bad = {"mkl", NULL};
    CHECK(fc_homogenize(frame, &bad, abd, NULL) == FC_ERROR &&
              strstr(fc_last_error(), "unknown solver") != NULL,
          "unknown solver: %s", fc_last_error());
    fc_model_free(frame);
    /* A singular matrix: [[1,1],[1,1]]. */
    const size_t col_ptr[] = {0, 2, 4};
    const size_t row_idx[] = {0, 1, 0, 1};
    const double values[] = {1, 1, 1, 1};
    FcSolver *s = NULL;
    CHECK(fc_solver_new(NULL, &s) == FC_OK, "solver");
    double x[2], b[2] = {1, 2};
    CHECK(fc_solver_solve(s, b, x, NULL) == FC_INVALID_ARGUMENT, "solve before factorize");
    FcStatus st = fc_solver_factorize(s, 2, col_ptr, row_idx, values);
    if (st == FC_OK) {
        st = fc_solver_solve(s, b, x, NULL);
    }
    CHECK(st == FC_ERROR && strlen(fc_last_error()) > 0, "singular: %d", (int)st);
    /* Unsorted rows within a column break the CSC contract. */
    const size_t bad_rows[] = {1, 0, 0, 1};
    CHECK(fc_solver_factorize(s, 2, col_ptr, bad_rows, values) == FC_ERROR, "unsorted rows");
    fc_solver_free(s);
    fc_model_free(NULL);
    fc_solver_free(NULL);
    fc_string_free(NULL);
}

int main(void) {
    CHECK(strlen(fc_version()) > 0, "version");
    homogenize_matches_the_closed_form();
    curve_and_generators_run();
    the_solver_layer_solves_a_known_system();
    the_stateful_cell_updates_and_tries();
    errors_are_statuses_with_messages();
    printf("test result: %s. %d passed; %d failed; C ABI %s\n", failed ? "FAILED" : "ok", passed,
           failed, fc_version());
    return failed ? 1 : 0;
}
