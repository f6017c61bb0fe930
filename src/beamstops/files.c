/* What standard Fortran cannot ask of the file system (used by src/beamstops/files.f90). */
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

/* 1 when the paths name the same file (same device and inode: a hard link, a symbolic
   link or another spelling of one path), 0 otherwise or when either does not exist. */
int beamstops_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) != 0 || stat(b, &sb) != 0)
        return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

/* 1 when the path exists and is a directory. */
int beamstops_is_directory(const char *path)
{
    struct stat s;
    return stat(path, &s) == 0 && S_ISDIR(s.st_mode);
}

/* What is at path, the link itself when it is a symbolic link (lstat), or with `follow` what it
   leads to (stat): 0 nothing (or nothing the process can see), 1 a regular file, 2 a symbolic
   link, 3 a folder, 4 a FIFO, 5 a socket, 6 a device, 7 anything else. */
int beamstops_path_kind(const char *path, int follow)
{
    struct stat s;
    if ((follow ? stat(path, &s) : lstat(path, &s)) != 0)
        return 0;
    if (S_ISREG(s.st_mode))
        return 1;
    if (S_ISLNK(s.st_mode))
        return 2;
    if (S_ISDIR(s.st_mode))
        return 3;
    if (S_ISFIFO(s.st_mode))
        return 4;
    if (S_ISSOCK(s.st_mode))
        return 5;
    if (S_ISCHR(s.st_mode) || S_ISBLK(s.st_mode))
        return 6;
    return 7;
}

/* An exclusive flock lock on the regular file at path, taken without waiting (LOCK_NB) on a
   descriptor of its own, opened read-only, never through a symbolic link (O_NOFOLLOW), never
   waiting on a FIFO (O_NONBLOCK), never created nor truncated. Returns the descriptor that holds the lock (>= 0; closing it releases the lock), -1 when
   another open file holds a lock on the file (HDF5 locks every file it has open: another run
   writing it, or a program reading it), -2 when the file cannot be opened or locked otherwise
   (missing, a file system without locks: no lock is held). */
int beamstops_lock_file(const char *path)
{
    int fd, busy;
    do
        fd = open(path, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    while (fd < 0 && errno == EINTR);
    if (fd < 0)
        return -2;
    while (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        if (errno == EINTR)
            continue;
        busy = errno == EWOULDBLOCK;
        close(fd);
        return busy ? -1 : -2;
    }
    return fd;
}

/* Release a lock of beamstops_lock_file (close its descriptor). */
void beamstops_unlock_file(int fd)
{
    if (fd >= 0)
        close(fd);
}

/* 1 when another open file holds a flock lock on the existing file at path (beamstops_lock_file
   would give -1), 0 otherwise; the probe's own lock is released at once. */
int beamstops_file_in_use(const char *path)
{
    int fd = beamstops_lock_file(path);
    beamstops_unlock_file(fd);
    return fd == -1;
}

/* 0 when HDF5 will not lock the files it opens: HDF5_USE_FILE_LOCKING set to FALSE or 0 (HDF5
   1.10.7 and later read both; earlier ones FALSE only), else 1. */
int beamstops_hdf5_locks(void)
{
    const char *value = getenv("HDF5_USE_FILE_LOCKING");
    return value == NULL || (strcmp(value, "FALSE") != 0 && strcmp(value, "0") != 0);
}

/* The folder part of a path (".", "/" or the path up to its last slash) into dir, and a
   pointer to its last component. */
static const char *split_path(const char *path, char *dir, size_t size)
{
    const char *slash = strrchr(path, '/');
    size_t n;
    if (slash == NULL) {
        snprintf(dir, size, ".");
        return path;
    }
    n = (size_t)(slash - path);
    if (n == 0)
        n = 1; /* "/name": the root */
    if (n >= size)
        n = size - 1;
    memcpy(dir, path, n);
    dir[n] = '\0';
    return slash + 1;
}

/* 1 when the two paths name one file, whether or not it exists yet: the same existing file
   (beamstops_same_file), or the same name in the same existing folder however the folder is
   spelt ("out.h5", "./out.h5", "sub/../out.h5"); 0 otherwise. */
int beamstops_same_path(const char *a, const char *b)
{
    struct stat sa, sb;
    const char *name_a, *name_b;
    char *dir_a, *dir_b;
    size_t la = strlen(a) + 2, lb = strlen(b) + 2;
    int same = 0;
    if (beamstops_same_file(a, b))
        return 1;
    dir_a = malloc(la);
    dir_b = malloc(lb);
    if (dir_a != NULL && dir_b != NULL) {
        name_a = split_path(a, dir_a, la);
        name_b = split_path(b, dir_b, lb);
        if (strcmp(name_a, name_b) == 0) {
            if (strcmp(dir_a, dir_b) == 0)
                same = 1;
            else if (stat(dir_a, &sa) == 0 && stat(dir_b, &sb) == 0)
                same = sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
        }
    }
    free(dir_a);
    free(dir_b);
    return same;
}

/* Remove the file at path in a process of its own that this one does not wait for (forked twice,
   in a session of its own, so that it is neither a zombie of this process nor stopped by a Ctrl-C
   meant for it; with no file descriptor open, so that a caller reading this process's output
   through a pipe does not wait for it either); here, when no process can be started. The
   children call only async-signal-safe functions. */
static void remove_detached(const char *path)
{
    pid_t child = fork();
    int status = 1;
    if (child == 0) {
        pid_t grandchild = fork();
        if (grandchild == 0) {
            setsid();
#if defined(SYS_close_range)
            if (syscall(SYS_close_range, 0U, ~0U, 0U) != 0)
#endif
                for (int fd = 0; fd < 1024; fd++)
                    close(fd);
            unlink(path);
            _exit(0);
        }
        _exit(grandchild < 0);
    }
    if (child > 0)
        while (waitpid(child, &status, 0) < 0 && errno == EINTR)
            ;
    if (child < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        unlink(path);
}

/* Rename `from` to `to` only when nothing is at `to`: 0 done, else -1 with errno (EEXIST when
   something is there). renameat2's RENAME_NOREPLACE where the kernel and the file system have it;
   else a hard link and the removal of the old name; else, on a file system without hard links, a
   rename once lstat found nothing there. */
static int rename_no_replace(const char *from, const char *to)
{
    struct stat s;
#if defined(SYS_renameat2)
    if (syscall(SYS_renameat2, AT_FDCWD, from, AT_FDCWD, to, 1U /* RENAME_NOREPLACE */) == 0)
        return 0;
    if (errno != EINVAL && errno != ENOSYS)
        return -1;
#endif
    if (link(from, to) == 0) {
        if (unlink(from) == 0)
            return 0;
        unlink(to);
        return -1;
    }
    if (errno == EEXIST)
        return -1;
    if (lstat(to, &s) == 0) {
        errno = EEXIST;
        return -1;
    }
    return rename(from, to);
}

/* Move the finished file `from` onto `to`. A regular file at `to` (an earlier output) is renamed
   aside first, to a hidden name beside it that nothing has (`.NAME.replaced-PID`, or with `-K`
   after it when that is taken: never over another file), `from` renamed onto `to`, and
   the earlier file removed by a process of its own (remove_detached): removing it costs the
   kernel the freeing of its pages and blocks, 14-15 ms for the Figure 4 run's 145 MB, which a
   run into an existing output paid at its end (scripts/bench_rerun.py: a re-run of that scene
   took 15.6 ms more than a run into a fresh folder, now none measurable). Renaming onto the
   existing file instead would make
   ext4 (its default auto_da_alloc) write the new file's data out first: 0.12-0.27 s (strace -T).
   For a moment `to` does not exist, and after a power cut the new file may be incomplete where
   a rename onto it would have kept the old one; an output can be run again, so outputs take
   this and checkpoints keep the atomic rename. When `from` cannot be renamed, the earlier file
   is put back. 0 on success, -1 otherwise (`from` then stays where it is). */
int beamstops_replace_file(const char *from, const char *to)
{
    struct stat s;
    const char *name;
    char *aside;
    size_t length;
    int k, moved = 0;
    if (lstat(to, &s) != 0 || !S_ISREG(s.st_mode))
        return rename(from, to) == 0 ? 0 : -1;
    length = strlen(to) + 64;
    aside = malloc(length);
    if (aside != NULL) {
        name = strrchr(to, '/');
        name = name == NULL ? to : name + 1;
        for (k = 0; k < 1000 && !moved; k++) {
            if (k == 0)
                snprintf(aside, length, "%.*s.%s.replaced-%ld", (int)(name - to), to, name, (long)getpid());
            else
                snprintf(aside, length, "%.*s.%s.replaced-%ld-%d", (int)(name - to), to, name, (long)getpid(), k);
            moved = rename_no_replace(to, aside) == 0;
            if (!moved && errno != EEXIST)
                break;
        }
        if (moved) {
            if (rename(from, to) != 0) {
                rename_no_replace(aside, to);
                free(aside);
                return -1;
            }
            remove_detached(aside);
            free(aside);
            return 0;
        }
        free(aside);
    }
    unlink(to); /* a failure shows in the rename, which then replaces it */
    return rename(from, to) == 0 ? 0 : -1;
}

/* The whole content of the file at path, read to its end in chunks: a regular file, or a pipe,
   a FIFO or a device, whose size is known only at its end (their stat size is 0). On success
   (0) *data holds *size bytes (to be released with free) and *regular says whether it is a
   regular file. Otherwise nothing is kept and the return says why: 1 no such file, 2 a folder,
   3 more than limit bytes (*size then the size a regular file reports, -1 for a stream, which is
   read no further than limit + 1 bytes), 4 it cannot be opened, 5 it cannot be read (the system's
   words in message, of message_size bytes). */
int beamstops_read_file(const char *path, int64_t limit, char **data, int64_t *size, int *regular,
                        char *message, int message_size)
{
    struct stat s;
    size_t capacity, used = 0;
    char *buffer, *grown;
    ssize_t n;
    int fd, failure = 0;
    *data = NULL;
    *size = 0;
    *regular = 0;
    do
        fd = open(path, O_RDONLY | O_CLOEXEC);
    while (fd < 0 && errno == EINTR);
    if (fd < 0 && errno == ENOENT)
        return 1;
    if (fd >= 0 && fstat(fd, &s) != 0) {
        failure = errno;
        close(fd);
        fd = -1;
        errno = failure;
    }
    if (fd < 0) {
        snprintf(message, (size_t)message_size, "%s", strerror(errno));
        return 4;
    }
    if (S_ISDIR(s.st_mode)) {
        close(fd);
        return 2;
    }
    *regular = S_ISREG(s.st_mode);
    if (*regular && s.st_size > limit) {
        *size = (int64_t)s.st_size;
        close(fd);
        return 3;
    }
    capacity = (*regular && s.st_size > 0 ? (size_t)s.st_size : 65536) + 1;
    buffer = malloc(capacity);
    if (buffer == NULL) {
        close(fd);
        snprintf(message, (size_t)message_size, "%s", strerror(ENOMEM));
        return 5;
    }
    while ((int64_t)used <= limit) {
        if (used == capacity) {
            capacity = 2 * capacity > (size_t)limit + 1 ? (size_t)limit + 1 : 2 * capacity;
            grown = realloc(buffer, capacity);
            if (grown == NULL) {
                failure = ENOMEM;
                break;
            }
            buffer = grown;
        }
        n = read(fd, buffer + used, capacity - used);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            failure = errno;
            break;
        }
        if (n == 0)
            break;
        used += (size_t)n;
    }
    close(fd);
    if (failure == 0 && (int64_t)used <= limit) {
        *data = buffer;
        *size = (int64_t)used;
        return 0;
    }
    free(buffer);
    if (failure != 0) {
        snprintf(message, (size_t)message_size, "%s", strerror(failure));
        return 5;
    }
    *size = *regular ? (int64_t)used : -1;
    return 3;
}

/* 0 when a run can write the file `path` and rename it in its folder, else the errno that says
   why not (ENAMETOOLONG, ENOENT, ENOTDIR, EACCES, EROFS, ...). A new file is created and removed
   again (O_EXCL: only what this call created is removed); an existing one is not opened, only
   tested for writing, with its folder (where the finished file is renamed). */
int beamstops_creation_errno(const char *path)
{
    size_t size = strlen(path) + 2;
    char *dir;
    int fd, code = 0;
    if (access(path, F_OK) != 0) {
        fd = open(path, O_WRONLY | O_CREAT | O_EXCL, 0666);
        if (fd < 0) /* created since by another process (a run started at the same time): the
                       recorder's exclusive creation tells who has it */
            return errno == EEXIST ? 0 : errno;
        close(fd);
        unlink(path);
        return 0;
    }
    if (access(path, W_OK) != 0)
        return errno;
    dir = malloc(size);
    if (dir == NULL)
        return ENOMEM;
    split_path(path, dir, size);
    if (access(dir, W_OK | X_OK) != 0)
        code = errno;
    free(dir);
    return code;
}

/* The system's text of an errno (strerror) into `text`, NUL-terminated within `size` bytes. */
void beamstops_errno_text(int code, char *text, size_t size)
{
    snprintf(text, size, "%s", strerror(code));
}

/* An HDF5 file killed while HDF5 flushed it may carry metadata written after the last
   superblock: chunk indexes pointing past the end-of-allocation address (EOA) the superblock
   records, which HDF5 then refuses ("addr overflow"). Everything the process wrote is in the file
   (a killed process loses nothing it wrote), so raising the EOA to the file's size makes those
   addresses valid again, as `h5clear --increment=0` does. Superblock versions 0 and 1 only (the
   program's files; later versions carry a checksum), 8-byte addresses, at byte 0. Returns 1 when
   the EOA was raised, 0 when the file needs nothing, -1 when it is not such a file or cannot be
   written. */
int beamstops_raise_hdf5_eoa(const char *path)
{
    static const unsigned char signature[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    unsigned char head[52], word[8];
    struct stat s;
    uint64_t eoa = 0, size;
    int fd = open(path, O_RDWR), version, at, k, outcome = -1;
    if (fd < 0)
        return -1;
    if (fstat(fd, &s) == 0 && pread(fd, head, sizeof head, 0) == (ssize_t)sizeof head &&
        memcmp(head, signature, 8) == 0 && head[13] == 8 && (head[8] == 0 || head[8] == 1)) {
        version = head[8];
        at = version == 0 ? 40 : 44; /* after the base and free-space addresses */
        for (k = 7; k >= 0; k--)
            eoa = (eoa << 8) | head[at + k];
        size = (uint64_t)s.st_size;
        outcome = 0;
        if (size > eoa) {
            for (k = 0; k < 8; k++)
                word[k] = (unsigned char)(size >> (8 * k));
            outcome = pwrite(fd, word, 8, at) == 8 ? 1 : -1;
        }
    }
    close(fd);
    return outcome;
}
