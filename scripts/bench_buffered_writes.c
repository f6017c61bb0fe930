/* The kernel's cost of appending an output through the page cache, as the HDF5 writer thread
   does (docs/performance_notes.md, "The writer thread's work slows the loop"): 145 MB written
   in blocks, with or without the blocks reserved first (fallocate with FALLOC_FL_KEEP_SIZE, as
   src/beamstops/recorder/disk_space.c), from an offset, with a gap between blocks; prints the
   CPU time of the writes (user + system, the reservation and the closing truncation included).

       cc -O2 scripts/bench_buffered_writes.c -o /tmp/writes
       /tmp/writes 131072 0 0 0      # 128 KB blocks, no reservation
       /tmp/writes 131072 1 0 0      # the same, reserved first
       /tmp/writes 131072 1 1234 0   # reserved, the blocks not on page boundaries
       /tmp/writes 131072 1 0 4096   # reserved, a page between blocks

   Arguments: block bytes, reserve (0 or 1), first offset, gap. Writes f.bin in the current
   folder and removes it. Linux only. */
#define _GNU_SOURCE
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

static double cpu_seconds(void)
{
    struct rusage r;
    getrusage(RUSAGE_SELF, &r);
    return r.ru_utime.tv_sec + r.ru_stime.tv_sec + 1e-6 * (r.ru_utime.tv_usec + r.ru_stime.tv_usec);
}

int main(int argc, char **argv)
{
    const size_t total = 145000000;
    size_t block, offset, gap, written;
    int reserve, fd;
    char *buffer;
    double start;
    if (argc != 5) {
        fprintf(stderr, "usage: %s BLOCK RESERVE OFFSET GAP\n", argv[0]);
        return 2;
    }
    block = strtoul(argv[1], NULL, 10);
    reserve = atoi(argv[2]);
    offset = strtoul(argv[3], NULL, 10);
    gap = strtoul(argv[4], NULL, 10);
    if (block == 0 || (buffer = aligned_alloc(4096, (block + 4095) / 4096 * 4096)) == NULL) {
        fprintf(stderr, "%s: BLOCK must be a positive number of bytes\n", argv[0]);
        return 2;
    }
    memset(buffer, 1, block);
    unlink("f.bin");
    start = cpu_seconds();
    fd = open("f.bin", O_CREAT | O_WRONLY | O_TRUNC, 0644);
    if (fd < 0) {
        perror("f.bin");
        return 1;
    }
    if (reserve)
        fallocate(fd, FALLOC_FL_KEEP_SIZE, 0, (off_t)(offset + total / block * (block + gap) + 8 * block));
    for (written = 0; written < total; written += block, offset += block + gap)
        if (pwrite(fd, buffer, block, (off_t)offset) != (ssize_t)block) {
            perror("pwrite");
            return 1;
        }
    if (reserve && ftruncate(fd, (off_t)(offset - gap)) != 0)
        perror("ftruncate");
    close(fd);
    printf("block %zu reserve %d first offset %s gap %zu: %.1f ms of CPU\n", block, reserve, argv[3], gap,
           1e3 * (cpu_seconds() - start));
    unlink("f.bin");
    free(buffer);
    return 0;
}
