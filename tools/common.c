/* common.c: input, output and error handling shared by the mlod-* tools. */
#define _POSIX_C_SOURCE 200809L
#define _XOPEN_SOURCE 700 /* realpath, S_ISSOCK */

#include "common.h"

#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

const char *tool_name = "mlod";

/* Inputs larger than this are refused rather than read into memory. */
#define MAX_INPUT_SIZE ((size_t)2 << 30)

/* "tool: what: message" on stderr, what (a file's name) escaped as in the
 * reports, or left out when NULL. */
static void vmessage(const char *what, const char *fmt, va_list ap)
{
	fprintf(stderr, "%s: ", tool_name);
	if (what) {
		tool_put_name(stderr, what, 0);
		fputs(": ", stderr);
	}
	vfprintf(stderr, fmt, ap);
	fputc('\n', stderr);
}

void tool_die(int code, const char *what, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vmessage(what, fmt, ap);
	va_end(ap);
	exit(code);
}

void tool_note(const char *what, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vmessage(what, fmt, ap);
	va_end(ap);
}

void tool_usage_error(const char *fmt, ...)
{
	va_list ap;
	fprintf(stderr, "%s: ", tool_name);
	va_start(ap, fmt);
	vfprintf(stderr, fmt, ap);
	va_end(ap);
	fprintf(stderr, "\nTry '%s --help' for more information.\n", tool_name);
	exit(EXIT_USAGE);
}

void tool_option_error(int ch, const char *shortopts, char *const *argv)
{
	/* A short option's letter is optopt (argv[optind - 1] is the element
	 * before a bundle, or the bundle, or the program's name). A long
	 * option's is 0 (unknown), or its value (a missing or unwanted value):
	 * its element is argv[optind - 1], optind having moved past it; a
	 * missing value's option is always the last of its element. */
	const char *arg = argv[optind - 1];
	int is_long = strncmp(arg, "--", 2) == 0 && arg[2] != '\0';
	if (ch == ':') {
		if (is_long)
			tool_usage_error("option '%.*s' needs a value", (int)strcspn(arg, "="), arg);
		tool_usage_error("option '-%c' needs a value", optopt);
	}
	if (optopt > 0 && optopt < 256 && optopt != ':' && !strchr(shortopts, optopt))
		tool_usage_error("unknown option '-%c'", optopt);
	if (optopt != 0 && is_long && strchr(arg, '='))
		tool_usage_error("option '%.*s' takes no value", (int)strcspn(arg, "="), arg);
	tool_usage_error("unknown option '%s'", arg);
}

int tool_exit_code(mlod_result r)
{
	switch (r) {
	case MLOD_OK: return 0;
	case MLOD_ERR_INVALID_ARG: return EXIT_USAGE;
	case MLOD_ERR_UNSUPPORTED: return EXIT_UNSUPPORTED;
	case MLOD_ERR_IO:
	case MLOD_ERR_PARSE:
	case MLOD_ERR_NOMEM:
	case MLOD_ERR_LIMIT: return EXIT_INPUT;
	}
	return EXIT_INPUT;
}

static int is_stdio(const char *path)
{
	return path == NULL || strcmp(path, "-") == 0;
}

const char *tool_input_label(const char *path)
{
	return is_stdio(path) ? "<stdin>" : path;
}

void *tool_read_input(const char *path, size_t *size)
{
	const char *label = tool_input_label(path);
	FILE *f = stdin;
	if (!is_stdio(path)) {
		struct stat st;
		if (stat(path, &st) != 0)
			tool_die(EXIT_INPUT, label, "%s", strerror(errno));
		if (S_ISDIR(st.st_mode))
			tool_die(EXIT_INPUT, label, "is a directory");
		f = fopen(path, "rb");
		if (!f)
			tool_die(EXIT_INPUT, label, "%s", strerror(errno));
	} else if (isatty(fileno(stdin))) {
		tool_usage_error("no input: give a file, or pipe a glb, glTF or BVH into stdin");
	}
	size_t cap = 1 << 16, n = 0;
	char *buf = malloc(cap);
	if (!buf)
		tool_die(EXIT_INPUT, label, "out of memory");
	for (;;) {
		if (n == cap) {
			if (cap >= MAX_INPUT_SIZE)
				tool_die(EXIT_INPUT, label, "input larger than %zu bytes", MAX_INPUT_SIZE);
			char *grown = realloc(buf, cap * 2);
			if (!grown)
				tool_die(EXIT_INPUT, label, "out of memory");
			buf = grown;
			cap *= 2;
		}
		size_t got = fread(buf + n, 1, cap - n, f);
		if (got == 0)
			break;
		n += got;
	}
	if (ferror(f))
		tool_die(EXIT_INPUT, label, "read error: %s", strerror(errno));
	if (f != stdin)
		fclose(f);
	*size = n;
	return buf;
}

/* The directory part of path, for resolving a .gltf's external URIs. */
static char *dir_of(const char *path)
{
	if (is_stdio(path))
		return NULL;
	const char *slash = strrchr(path, '/');
	if (!slash)
		return strdup(".");
	size_t n = (size_t)(slash - path);
	char *d = malloc(n + 2);
	if (!d)
		return NULL;
	memcpy(d, path, n ? n : 1);
	d[n ? n : 1] = '\0';
	return d;
}

/* The reader's warnings (mlod_character.warnings: what it changed,
 * approximated or dropped of the input), one line each on stderr, with or
 * without a report. Their names are already quoted (no line breaks). */
void tool_note_lines(const char *what, const char *lines)
{
	size_t n;
	for (const char *w = lines, *l; (l = mlod_next_line(&w, &n));)
		tool_note(what, "%.*s", (int)n, l);
}

void tool_note_items(const char *what, const char *notes, const char *suffix)
{
	size_t ns = strlen(suffix);
	for (const char *w = notes; w && *w;) {
		const char *e = strstr(w, "; ");
		size_t n = e ? (size_t)(e - w) : strlen(w);
		if (n >= ns && memcmp(w + n - ns, suffix, ns) == 0)
			tool_note(what, "%.*s", (int)n, w);
		w += n + (e ? 2 : 0);
	}
}

static void put_warnings(const char *path, const mlod_character *c)
{
	tool_note_lines(tool_input_label(path), c->warnings);
}

/* Exits at a failed load, with the reader's message; a pack (mlod(5))
 * is pointed to the mlod-pack options that read one. */
static void load_failed(const char *path, mlod_result r, const mlod_error *err, const void *data, size_t size)
{
	if (size >= 4 && memcmp(data, MLOD_PACK_MAGIC, 4) == 0)
		tool_die(EXIT_UNSUPPORTED, tool_input_label(path),
		         "an mlod pack, not a glTF, glb or BVH file: mlod-pack --info prints it, mlod-pack -x unpacks it "
		         "to a glb");
	tool_die(tool_exit_code(r), tool_input_label(path), "%s", err->message);
}

void tool_load(const char *path, mlod_gltf **doc, mlod_character *c, mlod_record_input *in)
{
	size_t size;
	void *data = tool_read_input(path, &size);
	char *dir = dir_of(path);
	mlod_error err = {0};
	mlod_result r = mlod_record_load(data, size, dir, MLOD_RECORD_INPUT_CLIPS, doc, c, in, &err);
	free(dir);
	if (r != MLOD_OK)
		load_failed(path, r, &err, data, size);
	free(data);
	put_warnings(path, c);
}

void *tool_load_keep(const char *path, mlod_gltf **doc, mlod_character *c, mlod_record_input *in, size_t *size)
{
	void *data = tool_read_input(path, size);
	char *dir = dir_of(path);
	mlod_error err = {0};
	mlod_result r = mlod_record_load(data, *size, dir, 0, doc, c, in, &err);
	free(dir);
	if (r != MLOD_OK)
		load_failed(path, r, &err, data, *size);
	put_warnings(path, c);
	return data;
}

/* Writes all of data to an open descriptor; 0 on success, else errno. */
static int write_all(int fd, const void *data, size_t size)
{
	const char *p = data;
	while (size > 0) {
		ssize_t n = write(fd, p, size);
		if (n < 0) {
			if (errno == EINTR)
				continue;
			return errno;
		}
		p += n;
		size -= (size_t)n;
	}
	return 0;
}

/* A character device, FIFO or socket: opened and written in place (never
 * replaced); a terminal is refused for binary output, as stdout is. */
static void write_in_place(const char *path, const void *data, size_t size, int binary, int socket_file)
{
	int fd = -1;
	if (socket_file) { /* a Unix stream socket: connected to, not opened */
		struct sockaddr_un a = {.sun_family = AF_UNIX};
		if (strlen(path) >= sizeof a.sun_path)
			tool_die(EXIT_OUTPUT, path, "socket path too long");
		strcpy(a.sun_path, path);
		if ((fd = socket(AF_UNIX, SOCK_STREAM, 0)) >= 0 && connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
			int e = errno;
			close(fd);
			fd = -1;
			errno = e;
		}
	} else {
		fd = open(path, O_WRONLY | O_NOCTTY);
	}
	if (fd < 0)
		tool_die(EXIT_OUTPUT, path, "cannot open for writing: %s", strerror(errno));
	if (binary && isatty(fd)) {
		close(fd);
		tool_die(EXIT_USAGE, path, "refusing to write binary output to a terminal");
	}
	int e = write_all(fd, data, size);
	if (close(fd) != 0 && e == 0 && errno != EINTR)
		e = errno;
	if (e)
		tool_die(EXIT_OUTPUT, path, "write error: %s", strerror(e));
}

/* A regular file (old: its stat) or a new path (old NULL): a temporary
 * file in the same directory, then rename. what names the output in
 * messages (the path given). The temporary is DIR/.mlod-XXXXXX (mkstemp):
 * short, so that a name of NAME_MAX bytes can still be replaced. It gets
 * the replaced file's permission bits, owner and group (as far as the
 * user may give them: a group the user is not in, or another owner, stays
 * the user's), so that a private file stays private; a new file gets 0666
 * less the umask, as open(2) would give it. Hard links to the old file
 * keep the old contents (the rename makes a new file, as sed -i does). */
static void write_replace(const char *what, const char *path, const struct stat *old, const void *data, size_t size)
{
	const char *slash = strrchr(path, '/');
	size_t dn = slash ? (size_t)(slash - path) + 1 : 0;
	char *tmp = malloc(dn + sizeof ".mlod-XXXXXX");
	if (!tmp)
		tool_die(EXIT_OUTPUT, what, "out of memory");
	memcpy(tmp, path, dn);
	strcpy(tmp + dn, ".mlod-XXXXXX");
	int fd = mkstemp(tmp);
	if (fd < 0) {
		int e = errno;
		free(tmp);
		if (!old) /* the file itself could not be made: the same cause */
			tool_die(EXIT_OUTPUT, what, "cannot create: %s", strerror(e));
		tool_die(EXIT_OUTPUT, what, "cannot create a temporary file in %.*s to replace it atomically: %s",
		         slash ? (int)(slash == path ? 1 : slash - path) : 1, slash ? path : ".", strerror(e));
	}
	mode_t mode = old ? old->st_mode & 07777 : 0;
	if (!old) { /* mkstemp makes it 0600 */
		mode_t mask = umask(0);
		umask(mask);
		mode = 0666 & ~mask;
	} else if (fchown(fd, old->st_uid, old->st_gid) != 0) { /* EPERM: not the owner's to give */
		mode &= ~(mode_t)S_ISUID; /* another owner's set-user-ID bit is not the user's */
		if (fchown(fd, (uid_t)-1, old->st_gid) != 0)
			mode &= ~(mode_t)S_ISGID;
	}
	int e = fchmod(fd, mode) != 0 ? errno : 0;
	if (e == 0)
		e = write_all(fd, data, size);
	if (e == 0 && fsync(fd) != 0 && errno != EINVAL)
		e = errno;
	if (close(fd) != 0 && e == 0)
		e = errno;
	if (e == 0 && rename(tmp, path) != 0)
		e = errno;
	if (e) {
		remove(tmp);
		free(tmp);
		tool_die(EXIT_OUTPUT, what, "write failed: %s", strerror(e));
	}
	free(tmp);
}

/* Whether st is the file open on descriptor fd (the same device and
 * inode): -o /dev/stdout, /dev/fd/1 or /proc/self/fd/1 name the file the
 * shell redirected to, which must be written through that descriptor (at
 * its offset, after what the shell wrote), not replaced by name. */
static int same_file(const struct stat *st, int fd)
{
	struct stat f;
	return fstat(fd, &f) == 0 && f.st_dev == st->st_dev && f.st_ino == st->st_ino;
}

void tool_write_output(const char *path, const void *data, size_t size, int binary)
{
	/* A reader that goes away (a FIFO, socket or pipe closed early) is an
	 * output failure, exit 4, not a death by SIGPIPE. */
	signal(SIGPIPE, SIG_IGN);
	struct stat st;
	int open_on = 0; /* the descriptor path names, if stdout's or stderr's */
	if (!is_stdio(path) && stat(path, &st) == 0)
		open_on = same_file(&st, STDOUT_FILENO) ? STDOUT_FILENO : same_file(&st, STDERR_FILENO) ? STDERR_FILENO : 0;
	if (open_on == STDERR_FILENO) {
		if (binary && isatty(STDERR_FILENO))
			tool_die(EXIT_USAGE, path, "refusing to write binary output to a terminal");
		int e = write_all(STDERR_FILENO, data, size);
		if (e)
			tool_die(EXIT_OUTPUT, path, "write error: %s", strerror(e));
		return;
	}
	if (is_stdio(path) || open_on == STDOUT_FILENO) {
		if (binary && isatty(fileno(stdout)))
			tool_die(EXIT_USAGE, "<stdout>", "refusing to write binary output to a terminal; redirect stdout or use -o FILE");
		if (fwrite(data, 1, size, stdout) != size || fflush(stdout) != 0)
			tool_die(EXIT_OUTPUT, "<stdout>", "write error: %s", strerror(errno));
		return;
	}
	if (lstat(path, &st) != 0) {
		if (errno != ENOENT)
			tool_die(EXIT_OUTPUT, path, "%s", strerror(errno));
		write_replace(path, path, NULL, data, size); /* a new file */
		return;
	}
	char *target = NULL;
	/* A symbolic link stays; what it points to is written. */
	if (S_ISLNK(st.st_mode) && stat(path, &st) != 0)
		tool_die(EXIT_OUTPUT, path, "symbolic link to nothing that can be written (%s)", strerror(errno));
	if (S_ISDIR(st.st_mode))
		tool_die(EXIT_OUTPUT, path, "is a directory");
	if (S_ISREG(st.st_mode)) {
		/* The link's target is replaced in its own directory. */
		if (!(target = realpath(path, NULL)))
			tool_die(EXIT_OUTPUT, path, "cannot resolve: %s", strerror(errno));
		write_replace(path, target, &st, data, size);
	} else if (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode))
		write_in_place(path, data, size, binary, S_ISSOCK(st.st_mode));
	else
		tool_die(EXIT_OUTPUT, path, "not a regular file, character device or FIFO");
	free(target);
}

int tool_output_is_stdout(const char *path)
{
	struct stat st;
	if (is_stdio(path))
		return 1;
	/* /dev/null on both mixes nothing anyone reads; a terminal is refused
	 * binary output anyway. */
	return stat(path, &st) == 0 && !S_ISCHR(st.st_mode) && same_file(&st, STDOUT_FILENO);
}

int tool_ends_with(const char *s, const char *suffix)
{
	size_t a = strlen(s), b = strlen(suffix);
	return a >= b && strcmp(s + a - b, suffix) == 0;
}

enum tool_report tool_parse_report(const char *format)
{
	if (!format || strcmp(format, "table") == 0)
		return REPORT_TABLE;
	if (strcmp(format, "json") == 0)
		return REPORT_JSON;
	tool_usage_error("--report: unknown format '%s' (table or json)", format);
}

void tool_write_gltf(const char *path, const mlod_gltf *doc)
{
	int binary = is_stdio(path) || !tool_ends_with(path, ".gltf");
	void *data = NULL;
	size_t size = 0;
	mlod_error err = {0};
	if (mlod_gltf_write(doc, binary, &data, &size, &err) != MLOD_OK)
		tool_die(EXIT_OUTPUT, is_stdio(path) ? "<stdout>" : path, "%s", err.message);
	tool_write_output(path, data, size, binary);
	mlod_free(data);
}

/* value as a double: dies if it is not a number, or so close to 0 that
 * no double holds it (1e-400; a subnormal such as 1e-310 is a double); a
 * number too large for one (1e400) is returned as infinity (strtod's
 * HUGE_VAL), which the callers' ranges refuse as out of range. */
static double parse_number(const char *option, const char *value)
{
	char *end = NULL;
	errno = 0;
	double v = strtod(value, &end);
	if (end == value || *end != '\0' || isnan(v))
		tool_usage_error("%s: '%s' is not a number", option, value);
	if (errno == ERANGE && v == 0.0) /* underflow to 0: a number, but none a double holds */
		tool_usage_error("%s: %s is out of range (too close to 0 for a double)", option, value);
	return v;
}

double tool_parse_double(const char *option, const char *value, double lo, double hi)
{
	double v = parse_number(option, value);
	if (isinf(v) || v < lo || v > hi)
		tool_usage_error("%s: %s is out of range [%g, %g]", option, value, lo, hi);
	return v;
}

int tool_parse_int(const char *option, const char *value, int lo, int hi)
{
	double v = parse_number(option, value);
	if (isfinite(v) && v != floor(v)) /* before the range: 16.5 is not a whole number, whatever the range */
		tool_usage_error("%s: '%s' is not a whole number", option, value);
	if (v < lo || v > hi)
		tool_usage_error("%s: %s is out of range [%d, %d]", option, value, lo, hi);
	return (int)v;
}

double tool_parse_percent(const char *option, const char *value, double lo, double hi)
{
	size_t len = strlen(value);
	if (len == 0 || value[len - 1] != '%')
		return tool_parse_double(option, value, lo, hi);
	char *copy = malloc(len);
	if (!copy)
		tool_die(EXIT_USAGE, NULL, "out of memory");
	memcpy(copy, value, len - 1);
	copy[len - 1] = '\0';
	double v = tool_parse_double(option, copy, lo, hi);
	free(copy);
	return v;
}

const char *tool_input_stem(const char *path, const char *fallback, char *buf, size_t size)
{
	if (is_stdio(path))
		return fallback;
	const char *base = strrchr(path, '/');
	base = base ? base + 1 : path;
	const char *dot = strrchr(base, '.');
	size_t n = dot && dot != base ? (size_t)(dot - base) : strlen(base);
	snprintf(buf, size, "%.*s", (int)n, base);
	return buf;
}

int tool_parse_threads(const char *value)
{
	return tool_parse_int("--threads", value, 1, MLOD_MAX_THREADS);
}

void tool_json_string(FILE *f, const char *s)
{
	mlod_name_put(f, s, 1, 0);
}

void tool_put_name(FILE *f, const char *s, int width)
{
	mlod_name_put(f, s, 0, width);
}

void tool_put_line(FILE *f, const char *prefix, const char *s)
{
	fputs(prefix, f);
	mlod_name_put(f, s, 0, 0);
	fputc('\n', f);
}

void tool_put_lines(FILE *f, const char *prefix, const char *s)
{
	size_t n;
	for (const char *w = s, *l; (l = mlod_next_line(&w, &n));) {
		if (n == 0) /* as the library's reports: no empty note */
			continue;
		char *line = malloc(n + 1);
		if (!line)
			tool_die(EXIT_OUTPUT, NULL, "out of memory");
		memcpy(line, l, n);
		line[n] = 0;
		tool_put_line(f, prefix, line);
		free(line);
	}
}

int tool_name_width(const char *s)
{
	return mlod_name_put(NULL, s, 0, 0);
}

void tool_version(void)
{
	printf("%s (mlod) %s\n", tool_name, MLOD_VERSION);
	exit(0);
}

int tool_parse_list(const char *option, const char *value, double *out, int max, double lo, double hi)
{
	return tool_parse_list_percent(option, value, out, NULL, max, lo, hi);
}

int tool_parse_list_percent(const char *option, const char *value, double *out, int *percent, int max, double lo,
                            double hi)
{
	if (!*value)
		tool_usage_error("%s: empty list", option);
	int n = 0;
	char *copy = malloc(strlen(value) + 1);
	if (!copy)
		tool_die(EXIT_USAGE, NULL, "out of memory");
	strcpy(copy, value);
	for (char *tok = copy, *next; tok; tok = next) {
		next = strchr(tok, ',');
		if (next)
			*next++ = '\0';
		if (!*tok) /* "0.5,,0.25", "0.5,", ",0.5": strtok skipped these */
			tool_usage_error("%s: empty item in '%s'", option, value);
		if (n == max)
			tool_usage_error("%s: at most %d values", option, max);
		size_t len = strlen(tok);
		if (percent)
			percent[n] = len > 0 && tok[len - 1] == '%';
		if (percent && percent[n])
			tok[len - 1] = '\0';
		out[n++] = tool_parse_double(option, tok, lo, hi);
	}
	free(copy);
	return n;
}

int tool_drop_repeats(const char *option, double *v, int *percent, int n)
{
	int m = 0;
	for (int i = 0; i < n; i++) {
		int seen = 0;
		for (int j = 0; j < m && !seen; j++)
			seen = v[j] == v[i] && (!percent || percent[j] == percent[i]);
		if (seen) {
			tool_note(NULL, "%s: %g%s repeated: one level", option, v[i], percent && percent[i] ? "%" : "");
			continue;
		}
		if (percent)
			percent[m] = percent[i];
		v[m++] = v[i];
	}
	return m;
}
