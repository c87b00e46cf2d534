/* How fast this machine maps memory a process touches for the first time.
 *
 * Allocates 36 blocks of 52 MB one after the other (the size of the L cell problems'
 * seven right-hand sides) and writes each once: the time per block is the cost of its
 * first-touch page faults plus one write. On bare metal every block takes about the same;
 * on a VM whose host backs guest memory lazily (or takes freed pages back) the blocks past
 * the recently used pool cost several times more. Then frees them all and writes one more
 * block: memory the process just freed maps again at the cheap rate. Last, 512 MB mapped
 * fresh and zeroed in 256 KiB chunks as `extend_with_zeros` does, with and without asking the
 * kernel first to map each chunk's pages in one call (Linux 5.14's MADV_POPULATE_WRITE).
 *
 *   cc -O1 benches/fresh_pages.c -o /tmp/fresh_pages && /tmp/fresh_pages
 *
 * Results and what they mean for the L cell problems: docs/performance.md, "Memory touched
 * for the first time".
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/mman.h>

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23
#endif

/* Keeps the compiler from dropping writes to memory it can prove is read back only in part. */
static void touched(void *p) { __asm__ volatile("" : : "r"(p) : "memory"); }

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

int main(void) {
    const size_t block = (size_t)52 << 20;
    enum { BLOCKS = 36 };
    char *blocks[BLOCKS];
    long checksum = 0;
    double start = now();
    for (int i = 0; i < BLOCKS; i++) {
        double t = now();
        blocks[i] = malloc(block);
        if (!blocks[i]) {
            fprintf(stderr, "out of memory at block %d\n", i);
            return 1;
        }
        memset(blocks[i], i + 1, block);
        touched(blocks[i]);
        checksum += blocks[i][block / 2];
        printf("block %2d (%4zu MB held): %.3f s, %.0f MB/s\n", i, (size_t)i * 52, now() - t,
               52.0 / (now() - t));
    }
    printf("all %d MB: %.3f s\n", BLOCKS * 52, now() - start);
    for (int i = 0; i < BLOCKS; i++)
        free(blocks[i]);
    double t = now();
    char *again = malloc(block);
    if (!again)
        return 1;
    memset(again, 7, block);
    touched(again);
    checksum += again[block / 3];
    double dt = now() - t;
    printf("one block after freeing them: %.4f s, %.0f MB/s (checksum %ld)\n", dt, 52.0 / dt, checksum);
    free(again);
    const size_t fresh = (size_t)512 << 20, chunk = (size_t)256 << 10;
    for (int populate = 0; populate < 2; populate++) {
        char *p = mmap(NULL, fresh, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED)
            return 1;
        t = now();
        int refused = 0;
        for (size_t o = 0; o < fresh; o += chunk) {
            if (populate)
                refused |= madvise(p + o, chunk, MADV_POPULATE_WRITE) != 0;
            memset(p + o, 0, chunk);
        }
        touched(p);
        dt = now() - t;
        printf("512 MB zeroed in 256 KiB chunks%s: %.3f s%s\n",
               populate ? ", each mapped first by MADV_POPULATE_WRITE" : "", dt,
               refused ? " (the kernel refused the request)" : "");
        munmap(p, fresh);
    }
    return 0;
}
