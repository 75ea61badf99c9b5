/* File watching through Linux inotify: the viewer's live reload. Folders
 * are watched rather than files because editors save by writing a new file
 * and renaming it over the old one, which ends a watch on the file itself. */
#define _GNU_SOURCE
#include "core/core.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <unistd.h>

typedef struct watched_dir {
  int wd;
  char *path;
} watched_dir;

struct lm_watch {
  int fd;
  watched_dir *dirs;
  int dir_count, dir_cap;
  /* Events read but not yet handed out (one read() can return several). */
  char buf[16 * (sizeof(struct inotify_event) + NAME_MAX + 1)];
  ssize_t len, pos;
};

lm_watch *lm_watch_create(lm_error *err) {
  int fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (fd < 0) {
    lm_error_set(err, "file watching: inotify_init1 failed: %s", strerror(errno));
    return NULL;
  }
  lm_watch *w = lm_alloc(sizeof *w);
  w->fd = fd;
  return w;
}

void lm_watch_destroy(lm_watch *w) {
  if (!w) return;
  close(w->fd);
  for (int i = 0; i < w->dir_count; i++) free(w->dirs[i].path);
  free(w->dirs);
  free(w);
}

bool lm_watch_dir(lm_watch *w, const char *dir, lm_error *err) {
  /* A finished write or a rename into the folder: a file's new content is whole. */
  int wd = inotify_add_watch(w->fd, dir, IN_CLOSE_WRITE | IN_MOVED_TO);
  if (wd < 0) {
    lm_error_set(err, "%s: cannot watch: %s", dir, strerror(errno));
    return false;
  }
  for (int i = 0; i < w->dir_count; i++)
    if (w->dirs[i].wd == wd) return true; /* the same folder by another name */
  watched_dir *d = LM_PUSH(w->dirs, w->dir_count, w->dir_cap);
  d->wd = wd;
  d->path = lm_strdup(dir);
  return true;
}

bool lm_watch_next(lm_watch *w, char *path, size_t cap) {
  for (;;) {
    if (w->pos >= w->len) {
      w->len = read(w->fd, w->buf, sizeof w->buf);
      w->pos = 0;
      if (w->len <= 0) {
        w->len = 0;
        return false; /* EAGAIN: nothing pending */
      }
    }
    const struct inotify_event *e = (const struct inotify_event *)(w->buf + w->pos);
    w->pos += (ssize_t)(sizeof *e + e->len);
    if (!e->len) continue; /* an event on the folder itself */
    for (int i = 0; i < w->dir_count; i++) {
      if (w->dirs[i].wd == e->wd) {
        snprintf(path, cap, "%s/%s", w->dirs[i].path, e->name);
        return true;
      }
    }
  }
}
