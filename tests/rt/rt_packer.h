/*
 * rt_packer.h: for runtime tests that pack the samples with the mlod-pack
 * tool: where it is (MLOD_PACK, the repository's build/release, or next
 * to the test binary), a temporary folder, and SKIP with the reason when
 * either is missing. Include after rt_test.h, in one test file each.
 */
#ifndef RT_PACKER_H
#define RT_PACKER_H

#include <errno.h>
#include <stdint.h>
#include <unistd.h>

static char tmpdir[256];
static const char *mlod_pack_bin;
static char skip_why[512];

#define SKIP_IF_NO_PACK(name)                                                                  \
	do {                                                                                   \
		if (!mlod_pack_bin) {                                                          \
			printf("SKIP %s: %s\n", #name, skip_why);                              \
			return;                                                                \
		}                                                                              \
	} while (0)

static int file_exists(const char *p)
{
	return access(p, R_OK) == 0;
}

/* Runs mlod-pack on in (with options opts), writing tmpdir/out; 0 on success. */
static int run_pack(const char *in, const char *opts, const char *out, char *path, size_t cap)
{
	char cmd[2048];
	snprintf(path, cap, "%s/%s", tmpdir, out);
	snprintf(cmd, sizeof cmd, "'%s' %s '%s' -o '%s' >/dev/null 2>'%s/pack.err'", mlod_pack_bin, opts, in, path,
	         tmpdir);
	return system(cmd);
}

static uint8_t *read_all(const char *path, size_t *size)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	uint8_t *d = NULL;
	size_t n = 0, cap = 0;
	for (;;) {
		if (n == cap) {
			cap = cap ? 2 * cap : 1 << 16;
			uint8_t *t = realloc(d, cap);
			if (!t) {
				free(d);
				fclose(f);
				return NULL;
			}
			d = t;
		}
		size_t k = fread(d + n, 1, cap - n, f);
		n += k;
		if (k == 0)
			break;
	}
	fclose(f);
	*size = n;
	return d;
}

/* Finds mlod-pack and makes tmpdir ("TAG.XXXXXX" under TMPDIR or /tmp);
 * the samples named (NULL-terminated) must exist. Leaves mlod_pack_bin
 * NULL, and skip_why saying why, when anything is missing. */
static void rt_packer_setup(const char *argv0, const char *tag, const char *const *samples)
{
	const char *env = getenv("MLOD_PACK");
	static char guess[1024];
	if (env && *env)
		mlod_pack_bin = env;
	else if (file_exists("build/release/bin/mlod-pack"))
		mlod_pack_bin = "build/release/bin/mlod-pack";
	else if (argv0 && strlen(argv0) < 900) {
		/* build/<config>/tests/rt/<test> -> build/<config>/bin/mlod-pack */
		snprintf(guess, sizeof guess, "%s", argv0);
		char *slash = strrchr(guess, '/');
		if (slash) {
			snprintf(slash, sizeof guess - (size_t)(slash - guess), "/../../bin/mlod-pack");
			if (file_exists(guess))
				mlod_pack_bin = guess;
		}
	}
	if (!mlod_pack_bin) {
		snprintf(skip_why, sizeof skip_why, "no mlod-pack (set MLOD_PACK, or run from the repository after make)");
		return;
	}
	for (const char *const *s = samples; *s; s++)
		if (!file_exists(*s)) {
			snprintf(skip_why, sizeof skip_why, "no samples/ here (run from the repository's root)");
			mlod_pack_bin = NULL;
			return;
		}
	const char *t = getenv("TMPDIR");
	snprintf(tmpdir, sizeof tmpdir, "%s/%s.XXXXXX", t && *t && strlen(t) < 200 ? t : "/tmp", tag);
	if (!mkdtemp(tmpdir)) {
		snprintf(skip_why, sizeof skip_why, "mkdtemp: %s", strerror(errno));
		mlod_pack_bin = NULL;
	}
}

/* Removes tmpdir and what the tests packed into it. */
static void rt_packer_cleanup(void)
{
	if (tmpdir[0] && mlod_pack_bin) {
		char cmd[600];
		snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
		if (system(cmd) != 0)
			fprintf(stderr, "could not remove %s\n", tmpdir);
	}
}

#endif /* RT_PACKER_H */
