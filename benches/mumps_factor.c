/* MUMPS (Debian's sequential build, libmumps-seq-dev) on one exported cell matrix: the timings
 * that benches/factor_comparison.py reads, as one JSON line.
 *
 *   mumps_factor A.mtx REPEATS
 *
 * A is a Matrix Market `coordinate real symmetric` file (one triangle, as `fibercell
 * export-matrix` writes it). MUMPS takes it as an SPD matrix (SYM = 1) with its automatic
 * choice of ordering (ICNTL(7) = 7; Debian's build has SCOTCH and PORD, not METIS). The
 * analysis (JOB = 1) and the factorization (JOB = 2, on the last analysis) are each timed
 * REPEATS times and their medians reported, with nnz(L) (INFOG(29)), MUMPS's own count of
 * the elimination's operations (RINFOG(3)), the ordering used (INFOG(7)) and the backward
 * error of A x = A·1 as the script computes it for PARDISO. The dense kernels run on the
 * threads of the BLAS it links (OpenBLAS); this build has no OpenMP of its own.
 */
#define _POSIX_C_SOURCE 199309L /* clock_gettime under -std=c11 */
#include <dmumps_c.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define USE_COMM_WORLD -987654

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

static int by_value(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *v, int n) {
  qsort(v, n, sizeof *v, by_value);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static void fail(const char *what) {
  fprintf(stderr, "mumps_factor: %s\n", what);
  exit(1);
}

/* malloc or calloc's result, or the end of the program. */
static void *checked(void *p) {
  if (!p) fail("out of memory");
  return p;
}

/* The whole file, NUL-terminated. */
static char *slurp(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) fail("cannot open the matrix file");
  fseek(f, 0, SEEK_END);
  long size = ftell(f);
  if (size < 0) fail("cannot read the matrix file");
  fseek(f, 0, SEEK_SET);
  char *text = checked(malloc(size + 1));
  if (fread(text, 1, size, f) != (size_t)size) fail("cannot read the matrix file");
  text[size] = 0;
  fclose(f);
  return text;
}

static void call(DMUMPS_STRUC_C *id, int job) {
  id->job = job;
  dmumps_c(id);
  if (id->infog[0] < 0) {
    fprintf(stderr, "mumps_factor: JOB %d failed, INFOG(1) = %d, INFOG(2) = %d\n", job,
            id->infog[0], id->infog[1]);
    exit(1);
  }
}

int main(int argc, char **argv) {
  if (argc != 3) fail("usage: mumps_factor A.mtx REPEATS");
  int repeats = atoi(argv[2]);
  if (repeats < 1) fail("REPEATS must be at least 1");
  char *text = slurp(argv[1]);
  if (!strstr(text, "coordinate real symmetric")) fail("not a `coordinate real symmetric` file");
  /* Past the comments to the size line. */
  char *p = text;
  while (*p == '%') {
    p = strchr(p, '\n');
    if (!p) fail("no size line");
    p++;
  }
  char *end;
  long n = strtol(p, &end, 10);
  long ncols = strtol(end, &end, 10);
  long nnz = strtol(end, &end, 10);
  if (n <= 0 || nnz <= 0) fail("bad size line");
  if (ncols != n) fail("the matrix is not square");
  MUMPS_INT *irn = checked(malloc(nnz * sizeof *irn)), *jcn = checked(malloc(nnz * sizeof *jcn));
  double *a = checked(malloc(nnz * sizeof *a));
  double *b = checked(calloc(n, sizeof *b)), *row_sum = checked(calloc(n, sizeof *row_sum));
  for (long k = 0; k < nnz; k++) {
    irn[k] = strtol(end, &end, 10);
    jcn[k] = strtol(end, &end, 10);
    a[k] = strtod(end, &end);
    if (irn[k] < 1 || irn[k] > n || jcn[k] < 1 || jcn[k] > n) fail("entry out of range");
    if (!isfinite(a[k])) fail("a value is not finite");
    /* b = A·1 and the rows' absolute sums, both triangles. */
    b[irn[k] - 1] += a[k];
    row_sum[irn[k] - 1] += fabs(a[k]);
    if (irn[k] != jcn[k]) {
      b[jcn[k] - 1] += a[k];
      row_sum[jcn[k] - 1] += fabs(a[k]);
    }
  }
  free(text);

  DMUMPS_STRUC_C id;
  memset(&id, 0, sizeof id);
  id.comm_fortran = USE_COMM_WORLD;
  id.par = 1;
  id.sym = 1; /* SPD */
  call(&id, -1);
  id.icntl[0] = -1; /* no messages */
  id.icntl[1] = -1;
  id.icntl[2] = -1;
  id.icntl[3] = 0;
  id.icntl[6] = 7;   /* ICNTL(7): MUMPS's automatic choice of ordering */
  id.icntl[13] = 40; /* ICNTL(14): 40 % more working space than estimated */
  id.n = n;
  id.nnz = nnz;
  id.irn = irn;
  id.jcn = jcn;
  id.a = a;

  double *analyze = checked(malloc(repeats * sizeof *analyze));
  double *factorize = checked(malloc(repeats * sizeof *factorize));
  for (int r = 0; r < repeats; r++) {
    double t = now();
    call(&id, 1);
    analyze[r] = now() - t;
  }
  for (int r = 0; r < repeats; r++) {
    double t = now();
    call(&id, 2);
    factorize[r] = now() - t;
  }
  long nnz_factor = id.infog[28] >= 0 ? id.infog[28] : -1000000L * id.infog[28];
  double flops = id.rinfog[2];
  int ordering = id.infog[6];

  double *x = checked(malloc(n * sizeof *x));
  memcpy(x, b, n * sizeof *x);
  id.rhs = x;
  call(&id, 3);
  /* max |A x − b| / (max row sum · max |x| + max |b|), both triangles. */
  double *r = checked(calloc(n, sizeof *r));
  for (long k = 0; k < nnz; k++) {
    r[irn[k] - 1] += a[k] * x[jcn[k] - 1];
    if (irn[k] != jcn[k]) r[jcn[k] - 1] += a[k] * x[irn[k] - 1];
  }
  double res = 0, norm_a = 0, norm_x = 0, norm_b = 0;
  for (long i = 0; i < n; i++) {
    res = fmax(res, fabs(r[i] - b[i]));
    norm_a = fmax(norm_a, row_sum[i]);
    norm_x = fmax(norm_x, fabs(x[i]));
    norm_b = fmax(norm_b, fabs(b[i]));
  }
  call(&id, -2);

  static const char *names[] = {"AMD", "given", "AMF", "SCOTCH", "PORD", "METIS", "QAMD"};
  printf("{\"ordering\": \"%s (ICNTL(7) = 7, automatic)\", \"analyze_seconds\": %.9g, "
         "\"factorize_seconds\": %.9g, \"nnz_factor\": %ld, \"flops\": %.6g, "
         "\"backward_error\": %.3g}\n",
         ordering >= 0 && ordering <= 6 ? names[ordering] : "other", median(analyze, repeats),
         median(factorize, repeats), nnz_factor, flops, res / (norm_a * norm_x + norm_b));
  return 0;
}
