/* Disk space reserved ahead of a file that grows at its end (used by
   src/beamstops/recorder/disk_space.f90): blocks allocated past the end without moving it
   (fallocate with FALLOC_FL_KEEP_SIZE) before the writes reach them.
   - Speed: on ext4, a write into a reserved block skips the work of the delayed allocation on
     each block it passes (reserving, mapping and counting it): writing 145 MB in 128 KB writes
     took 24-27 ms of CPU without a reservation and 14-15 ms with it, the reservation included
     (scripts/bench_buffered_writes.c).
   - A full disk: a write that finds no room is refused before it starts, while the blocks reserved
     earlier still hold room for what closing the file writes, so that the file closes readable
     with the records written so far (a write that ran out of room halfway left HDF5 a file it
     could not open). The file-size limit (RLIMIT_FSIZE, `ulimit -f`) is checked the same way.
   Where the file system takes no reservation (NFS, a system without fallocate), only the limit
   is checked. Blocks reserved past the file's final end are released when the reservation ends:
   a truncation to the file's own size. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

/* A descriptor of the file at path for its reservation, or -1 (no reservation then). */
int beamstops_reservation_open(const char *path)
{
    int fd;
    do
        fd = open(path, O_WRONLY | O_CLOEXEC);
    while (fd < 0 && errno == EINTR);
    return fd;
}

/* Whether `bytes` more past the end of a file of `size` bytes stay within the file-size limit. */
static int within_size_limit(int64_t size, int64_t bytes)
{
    struct rlimit limit;
    if (getrlimit(RLIMIT_FSIZE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY)
        return 1;
    return size + bytes <= (int64_t)limit.rlim_cur;
}

/* Make sure that the `bytes` past the file's end are reserved: when they reach beyond
   `reserved` (the end of the last reservation), reserve `ahead` bytes (at least `bytes`) from
   the file's end, or only `bytes` when the disk has no room for `ahead`. Returns the new end of
   the reservation; -1 when the file system takes none (then, and when `reserved` is -1, only the
   file-size limit is checked from then on); -2 when there is no room for `bytes` (the disk is
   full, or the file-size limit is reached), the reservation left as it was. */
int64_t beamstops_reservation_extend(int fd, int64_t bytes, int64_t ahead, int64_t reserved)
{
    struct stat s;
    if (fd < 0 || fstat(fd, &s) != 0)
        return -1;
    if (!within_size_limit((int64_t)s.st_size, bytes))
        return -2;
    if (reserved == -1 || (int64_t)s.st_size + bytes <= reserved)
        return reserved;
    if (ahead < bytes)
        ahead = bytes;
#if defined(__linux__) && defined(FALLOC_FL_KEEP_SIZE)
    if (fallocate(fd, FALLOC_FL_KEEP_SIZE, s.st_size, ahead) == 0)
        return (int64_t)s.st_size + ahead;
    if (errno == ENOSPC || errno == EDQUOT) {
        if (fallocate(fd, FALLOC_FL_KEEP_SIZE, s.st_size, bytes) == 0)
            return (int64_t)s.st_size + bytes;
        if (errno == ENOSPC || errno == EDQUOT)
            return -2;
    }
#endif
    return -1;
}

/* End the reservation: release the blocks reserved past the file's end, close the descriptor. */
void beamstops_reservation_close(int fd)
{
    struct stat s;
    if (fd < 0)
        return;
    if (fstat(fd, &s) == 0) {
        int status;
        do
            status = ftruncate(fd, s.st_size);
        while (status != 0 && errno == EINTR);
    }
    close(fd);
}
