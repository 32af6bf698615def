/*
 * common.h: what every mlod-* tool shares: error reporting with the exit
 * codes of the pipeline, reading the input, and writing the output
 * atomically. Only the public API of libmlod is used; no tool parses
 * JSON (the stage record is read through lib/record).
 *
 * Exit codes: 0 success, 1 usage, 2 bad input, 3 unsupported input,
 * 4 output failure.
 */
#ifndef MLOD_TOOLS_COMMON_H
#define MLOD_TOOLS_COMMON_H

#include <stddef.h>
#include <stdio.h>

#include "mlod.h"

enum {
	EXIT_USAGE = 1,
	EXIT_INPUT = 2,
	EXIT_UNSUPPORTED = 3,
	EXIT_OUTPUT = 4
};

/* The tool's name for messages ("mlod-label"). Set once in main. */
extern const char *tool_name;

/* tool_note for each line of lines ("\n"-separated; NULL or "": none):
 * the reader's and the pack writer's warnings. */
void tool_note_lines(const char *what, const char *lines);

/* tool_note for each item of notes ("; "-separated, as a library's notes
 * for reports) that ends with suffix: the notes a shell user needs
 * without --report (mlod-bgm's dropped ratios). */
void tool_note_items(const char *what, const char *notes, const char *suffix);

/* Prints "tool: what: message" to stderr and exits with code. what (a
 * file's name) is escaped as tool_put_name does; it may be NULL (then
 * "tool: message"). */
void tool_die(int code, const char *what, const char *fmt, ...)
#if defined(__GNUC__)
	__attribute__((format(printf, 3, 4), noreturn))
#endif
	;

/* Prints "tool: what: message" to stderr (what, an input's name, escaped
 * as tool_put_name does; NULL: "tool: message") and goes on. */
void tool_note(const char *what, const char *fmt, ...)
#if defined(__GNUC__)
	__attribute__((format(printf, 2, 3)))
#endif
	;

/* Prints "tool: message" and a hint to run --help, then exits 1. */
void tool_usage_error(const char *fmt, ...)
#if defined(__GNUC__)
	__attribute__((format(printf, 1, 2), noreturn))
#endif
	;

/* After getopt_long (opterr 0, shortopts starting with ':') returned ch,
 * ':' or '?': prints which option was wrong ("unknown option '-k'",
 * "option '--output' needs a value") and exits 1. */
void tool_option_error(int ch, const char *shortopts, char *const *argv)
#if defined(__GNUC__)
	__attribute__((noreturn))
#endif
	;

/* The exit code for a library result met while reading input. */
int tool_exit_code(mlod_result r);

/* The name to use in messages for an input path (NULL or "-" is "<stdin>"). */
const char *tool_input_label(const char *path);

/* Reads a whole file, or stdin when path is NULL or "-". Exits 2 with a
 * clear message when it cannot (missing, a directory, unreadable, too big). */
void *tool_read_input(const char *path, size_t *size);

/* Reads and loads a glb, glTF or BVH input through the stage record
 * (mlod_record_load: a BVH's document says it is one; the clips are the
 * input's, without the motion level animations); exits on failure. doc
 * and in may be NULL. The reader's warnings (what it changed, approximated
 * or dropped of the input: mlod_character.warnings) go to stderr, one line
 * each. */
void tool_load(const char *path, mlod_gltf **doc, mlod_character *c, mlod_record_input *in);

/* tool_load that keeps the motion level animations among the clips (the
 * pack takes them as levels) and also returns the input's bytes (*size of
 * them; release with free). */
void *tool_load_keep(const char *path, mlod_gltf **doc, mlod_character *c, mlod_record_input *in, size_t *size);

/* Writes bytes to path, or to stdout when path is NULL or "-". A regular
 * file or a new path is replaced atomically (a temporary file in the same
 * directory, then rename); a symbolic link is kept and the file it resolves
 * to replaced so; a character device or FIFO is opened and written in
 * place, a Unix stream socket connected to and written. Binary output to
 * a terminal (stdout or path) is refused (exit 1). Exits 4 on failure. */
void tool_write_output(const char *path, const void *data, size_t size, int binary);

/* Whether output goes to standard output: NULL, "-", or a path naming the
 * file open on it (/dev/stdout, /dev/fd/1, the file stdout was redirected
 * to; not a character device such as /dev/null). */
int tool_output_is_stdout(const char *path);

/* The end of every tool's --help: how -o writes (tool_write_output). */
#define TOOL_OUTPUT_NOTE \
	"-o replaces a regular file atomically (through a temporary file, its\n" \
	"mode, owner and group kept, hard links not; a symbolic link is kept\n" \
	"and the file it names replaced); a character\n" \
	"device, FIFO or Unix socket is written in place (binary output to a\n" \
	"terminal refused); /dev/stdout goes through standard output.\n"

/* Serialises doc as glb (or .gltf when path ends in ".gltf") to path or
 * stdout. Exits 4 on failure. */
void tool_write_gltf(const char *path, const mlod_gltf *doc);

/* Parses a double from an option value; exits 1 with a message naming the
 * option when it is not a finite number within [lo, hi]. */
double tool_parse_double(const char *option, const char *value, double lo, double hi);

/* Writes s as a JSON string literal to f: quote, backslash and control
 * characters escaped, a byte that is not well-formed UTF-8 as U+FFFD. */
void tool_json_string(FILE *f, const char *s);

/* Writes s (a name from the input or the pack, or a note) to f for a
 * table: \n, \t, \r, \\ and \xHH for any other control character, DEL
 * and a byte that is not UTF-8, padded with spaces to width columns (0:
 * none), each UTF-8 character one column, so that a name never breaks a
 * line or a column. */
void tool_put_name(FILE *f, const char *s, int width);

/* Writes prefix, s as tool_put_name does, and a newline. */
void tool_put_line(FILE *f, const char *prefix, const char *s);

/* tool_put_line for each line of s (the reader's notes, one a line): one
 * prefixed line each, so that no note shows as a literal \n. */
void tool_put_lines(FILE *f, const char *prefix, const char *s);

/* The columns tool_put_name takes for s, unpadded. */
int tool_name_width(const char *s);

/* Prints "tool (mlod) VERSION" to stdout and exits 0. */
void tool_version(void)
#if defined(__GNUC__)
	__attribute__((noreturn))
#endif
	;

/* What --report[=FORMAT] asked for. */
enum tool_report { REPORT_NONE, REPORT_TABLE, REPORT_JSON };

/* Parses the optional FORMAT of --report (NULL means table); exits 1 on an
 * unknown format. */
enum tool_report tool_parse_report(const char *format);

/* Does s end with suffix? */
int tool_ends_with(const char *s, const char *suffix);

/* Parses a comma-separated list of at most max numbers within [lo, hi]
 * into out; exits 1 naming the option when it or an item is empty, it is
 * too long or holds something else. Returns the count. */
int tool_parse_list(const char *option, const char *value, double *out, int max, double lo, double hi);
/* The same, where a value may end in '%': percent[i] says whether value i did. */
int tool_parse_list_percent(const char *option, const char *value, double *out, int *percent, int max, double lo,
                            double hi);

/* Drops each of v[0..n) equal to an earlier one (and of the same unit:
 * percent[i], when percent is not NULL), which would make a second,
 * identical level, with a note on stderr; returns the count left. */
int tool_drop_repeats(const char *option, double *v, int *percent, int n);

/* Parses a whole number within [lo, hi]; exits 1 naming the option
 * otherwise ("not a whole number" before "out of range"). */
int tool_parse_int(const char *option, const char *value, int lo, int hi);

/* tool_parse_double for a value documented in percent: a trailing '%'
 * is allowed ("1%" is 1). */
double tool_parse_percent(const char *option, const char *value, double lo, double hi);

/* The file name of path without its directory and extension ("walk" for
 * "a/walk.bvh") in buf; fallback when path is NULL or "-". */
const char *tool_input_stem(const char *path, const char *fallback, char *buf, size_t size);

/* Parses -j/--threads: a whole number from 1 to MLOD_MAX_THREADS; exits 1
 * naming the option otherwise. The tools default to mlod_thread_count(). */
int tool_parse_threads(const char *value);

#endif
