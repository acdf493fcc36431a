/* LD_PRELOAD shim for the output-set test: symlink(2) fails with EPERM, as on FAT or a share
   without links, so that pxf's file-by-file fallback runs. */
#include <errno.h>

int symlink(const char* target, const char* path) {
  (void)target;
  (void)path;
  errno = EPERM;
  return -1;
}

int symlinkat(const char* target, int dirfd, const char* path) {
  (void)target;
  (void)dirfd;
  (void)path;
  errno = EPERM;
  return -1;
}
