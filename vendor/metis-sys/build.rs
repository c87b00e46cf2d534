//! Builds the vendored METIS and GKlib as metis-sys 0.3.2 does (32-bit indices and reals,
//! optimized in every profile), with `USE_GKRAND`: GKlib's own generator, made thread-local
//! in `random.c` (PATCHES.md), instead of the C library's process-wide `rand`.

use std::env;
use std::path::PathBuf;

const LIBMETIS: &[&str] = &[
    "auxapi.c",
    "balance.c",
    "bucketsort.c",
    "checkgraph.c",
    "coarsen.c",
    "compress.c",
    "contig.c",
    "debug.c",
    "fm.c",
    "fortran.c",
    "frename.c",
    "gklib.c",
    "graph.c",
    "initpart.c",
    "kmetis.c",
    "kwayfm.c",
    "kwayrefine.c",
    "mcutil.c",
    "mesh.c",
    "meshpart.c",
    "minconn.c",
    "mincover.c",
    "mmd.c",
    "ometis.c",
    "options.c",
    "parmetis.c",
    "pmetis.c",
    "refine.c",
    "separator.c",
    "sfm.c",
    "srefine.c",
    "stat.c",
    "timing.c",
    "util.c",
    "wspace.c",
];

const GKLIB: &[&str] = &[
    "b64.c",
    "blas.c",
    "cache.c",
    "csr.c",
    "error.c",
    "evaluate.c",
    "fkvkselect.c",
    "fs.c",
    "getopt.c",
    "gk_util.c",
    "gkregex.c",
    "graph.c",
    "htable.c",
    "io.c",
    "itemsets.c",
    "mcore.c",
    "memory.c",
    "pqueue.c",
    "random.c",
    "rw.c",
    "seq.c",
    "sort.c",
    "string.c",
    "timers.c",
    "tokenizer.c",
];

fn main() {
    let vendor = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("vendor");
    println!("cargo:rerun-if-changed={}", vendor.display());
    let mut build = cc::Build::new();
    build
        .define("IDXTYPEWIDTH", Some("32"))
        .define("REALTYPEWIDTH", Some("32"))
        .define("USE_GKRAND", None)
        .define("NDEBUG", None)
        .define("NDEBUG2", None)
        .opt_level(3)
        .include(vendor.join("metis/include"));
    for (dir, files) in [("metis/libmetis", LIBMETIS), ("GKlib", GKLIB)] {
        let root = vendor.join(dir);
        build.files(files.iter().map(|f| root.join(f)));
        build.include(root);
    }
    let target = env::var("TARGET").unwrap_or_default();
    if target.contains("linux") {
        build
            .define("LINUX", None)
            .define("_FILE_OFFSET_BITS", Some("64"));
    } else if target.contains("apple") {
        build.define("MACOS", None);
    }
    // METIS's sources warn a great deal; the warnings tell a user of fibercell nothing.
    build.warnings(false);
    build.compile("fibercell_metis");
}
