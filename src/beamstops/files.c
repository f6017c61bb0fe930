/* What standard Fortran cannot ask of the file system (used by src/beamstops/files.f90). */
#include <sys/stat.h>

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
