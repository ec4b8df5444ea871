/* semo_sim.c: the simulated platform (built only with -DSEMO_SIM).
 *
 * A scenario file gives, per robot, timed sensor values, battery levels and
 * service durations, the operator's commands, and faults. Sensor tasks read
 * the latest value (BATTERY, when no entry names it, the battery level at
 * that time); operator commands are delivered into the message queue at
 * their time by one thread. Link faults (drop, delay, partition) act on the
 * send path: semo_comm_send asks semo__sim_link for each robot it sends to,
 * and a delayed datagram is sent by a second thread at its time. Kill and
 * restart faults happen to the process from outside (a crash is not
 * something a program does to itself); they are checked here. The scenario
 * is read once, before any task runs, by a small strict JSON reader that
 * reports the line and column of a mistake.
 */
#define _POSIX_C_SOURCE 200809L

#include "semo_internal.h"

#ifdef SEMO_SIM

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SCENARIO_MAX_BYTES (16L * 1024 * 1024)
#define JSON_MAX_DEPTH 32
#define NAME_MAX_BYTES 48 /* sensor, service and command names */
#define DEFAULT_SERVICE_MS 100
#define MAX_MS 1000000000000000LL /* 31 000 years: keeps sums far from overflow */
#define MAX_LEVEL 1e15 /* a battery level's size: its rounding fits a long long */

/* ------------------------------------------------------------------ JSON */

typedef enum { J_NULL, J_BOOL, J_NUMBER, J_STRING, J_ARRAY, J_OBJECT } json_kind;

typedef struct json {
    json_kind kind;
    int line, col;
    bool boolean;
    double number;
    char *text;         /* J_STRING: the string; J_NUMBER: as written */
    struct json *items; /* J_ARRAY elements, J_OBJECT values */
    char **keys;        /* J_OBJECT */
    size_t count;
} json;

typedef struct {
    const char *s;
    size_t len, pos;
    int line, col;
    int depth;
    char error[200];
    int error_line, error_col;
} reader;

static bool fail_at(reader *r, int line, int col, const char *fmt, ...)
{
    if (r->error[0])
        return false; /* keep the first, innermost message */
    va_list args;
    va_start(args, fmt);
    vsnprintf(r->error, sizeof r->error, fmt, args);
    va_end(args);
    r->error_line = line;
    r->error_col = col;
    return false;
}

#define FAIL(r, ...) fail_at((r), (r)->line, (r)->col, __VA_ARGS__)

static int peek(const reader *r)
{
    return r->pos < r->len ? (unsigned char)r->s[r->pos] : -1;
}

static void advance(reader *r)
{
    if (r->s[r->pos] == '\n') {
        r->line++;
        r->col = 1;
    } else {
        r->col++;
    }
    r->pos++;
}

static void skip_space(reader *r)
{
    int c;
    while ((c = peek(r)) == ' ' || c == '\t' || c == '\n' || c == '\r')
        advance(r);
}

static void json_free(json *v)
{
    free(v->text);
    for (size_t i = 0; i < v->count; i++) {
        json_free(&v->items[i]);
        if (v->keys)
            free(v->keys[i]);
    }
    free(v->items);
    free(v->keys);
}

/* A growable byte buffer for strings. */
typedef struct {
    char *data;
    size_t len, cap;
} text_buf;

static bool put_byte(text_buf *b, unsigned char c)
{
    if (b->len + 1 >= b->cap) {
        size_t cap = b->cap ? b->cap * 2 : 32;
        char *grown = realloc(b->data, cap);
        if (!grown)
            return false;
        b->data = grown;
        b->cap = cap;
    }
    b->data[b->len++] = (char)c;
    b->data[b->len] = '\0';
    return true;
}

static bool put_code_point(text_buf *b, unsigned long cp)
{
    if (cp < 0x80)
        return put_byte(b, (unsigned char)cp);
    if (cp < 0x800)
        return put_byte(b, (unsigned char)(0xC0 | (cp >> 6))) && put_byte(b, (unsigned char)(0x80 | (cp & 0x3F)));
    if (cp < 0x10000)
        return put_byte(b, (unsigned char)(0xE0 | (cp >> 12))) &&
               put_byte(b, (unsigned char)(0x80 | ((cp >> 6) & 0x3F))) &&
               put_byte(b, (unsigned char)(0x80 | (cp & 0x3F)));
    return put_byte(b, (unsigned char)(0xF0 | (cp >> 18))) && put_byte(b, (unsigned char)(0x80 | ((cp >> 12) & 0x3F))) &&
           put_byte(b, (unsigned char)(0x80 | ((cp >> 6) & 0x3F))) && put_byte(b, (unsigned char)(0x80 | (cp & 0x3F)));
}

static bool read_hex4(reader *r, unsigned long *out)
{
    *out = 0;
    for (int i = 0; i < 4; i++) {
        int c = peek(r);
        int digit = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
        if (digit < 0)
            return FAIL(r, "expected four hexadecimal digits after \\u");
        *out = *out * 16 + (unsigned long)digit;
        advance(r);
    }
    return true;
}

/* At the opening quote; the string (escapes resolved) goes to `*out`. */
static bool read_string(reader *r, char **out)
{
    text_buf b = {0};
    advance(r);
    if (!put_byte(&b, 0))
        return FAIL(r, "out of memory");
    b.len = 0;
    for (;;) {
        int c = peek(r);
        if (c < 0) {
            free(b.data);
            return FAIL(r, "unterminated string");
        }
        if (c == '"') {
            advance(r);
            *out = b.data;
            return true;
        }
        if (c < 0x20) {
            free(b.data);
            return FAIL(r, "control character in a string (write it as an escape)");
        }
        bool ok = true;
        if (c != '\\') {
            ok = put_byte(&b, (unsigned char)c);
            advance(r);
        } else {
            advance(r);
            int e = peek(r);
            static const char escapes[] = "\"\\/bfnrt", decoded[] = "\"\\/\b\f\n\r\t";
            const char *simple = e > 0 ? strchr(escapes, e) : NULL;
            if (simple) {
                ok = put_byte(&b, (unsigned char)decoded[simple - escapes]);
                advance(r);
            } else if (e == 'u') {
                advance(r);
                unsigned long cp, low;
                ok = read_hex4(r, &cp);
                if (ok && cp >= 0xD800 && cp <= 0xDBFF) {
                    /* A surrogate pair spells a code point beyond U+FFFF. */
                    ok = peek(r) == '\\';
                    if (ok)
                        advance(r);
                    ok = ok && peek(r) == 'u';
                    if (ok)
                        advance(r);
                    ok = ok && read_hex4(r, &low) && low >= 0xDC00 && low <= 0xDFFF;
                    if (!ok)
                        FAIL(r, "unpaired surrogate in \\u escape");
                    else
                        cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
                } else if (ok && cp >= 0xDC00 && cp <= 0xDFFF) {
                    ok = FAIL(r, "unpaired surrogate in \\u escape");
                } else if (ok && cp == 0) {
                    ok = FAIL(r, "\\u0000 is not allowed in a scenario string");
                }
                ok = ok && put_code_point(&b, cp);
            } else {
                ok = FAIL(r, "unknown escape in a string");
            }
        }
        if (!ok) {
            free(b.data);
            return FAIL(r, "out of memory");
        }
    }
}

static bool read_value(reader *r, json *v);

static bool read_digits(reader *r)
{
    int c = peek(r);
    if (c < '0' || c > '9')
        return FAIL(r, "expected a digit");
    while ((c = peek(r)) >= '0' && c <= '9')
        advance(r);
    return true;
}

static bool read_number(reader *r, json *v)
{
    size_t start = r->pos;
    if (peek(r) == '-')
        advance(r);
    if (peek(r) == '0')
        advance(r); /* no leading zeros */
    else if (!read_digits(r))
        return false;
    if (peek(r) == '.') {
        advance(r);
        if (!read_digits(r))
            return false;
    }
    if (peek(r) == 'e' || peek(r) == 'E') {
        advance(r);
        if (peek(r) == '+' || peek(r) == '-')
            advance(r);
        if (!read_digits(r))
            return false;
    }
    size_t n = r->pos - start;
    v->text = malloc(n + 1);
    if (!v->text)
        return FAIL(r, "out of memory");
    memcpy(v->text, r->s + start, n);
    v->text[n] = '\0';
    v->kind = J_NUMBER;
    v->number = strtod(v->text, NULL);
    if (!isfinite(v->number))
        return fail_at(r, v->line, v->col, "number out of range");
    return true;
}

static bool read_word(reader *r, const char *word)
{
    for (const char *w = word; *w; w++) {
        if (peek(r) != *w)
            return FAIL(r, "unexpected character (expected a value)");
        advance(r);
    }
    return true;
}

/* Appends a zeroed element to an array or object being read. */
static json *push_item(reader *r, json *v, char *key)
{
    if ((v->count & (v->count - 1)) == 0) { /* 0, 1, 2, 4, ...: grow */
        size_t cap = v->count ? v->count * 2 : 1;
        json *items = realloc(v->items, cap * sizeof *items);
        if (items)
            v->items = items;
        char **keys = v->kind == J_OBJECT ? realloc(v->keys, cap * sizeof *keys) : NULL;
        if (keys)
            v->keys = keys;
        if (!items || (v->kind == J_OBJECT && !keys)) {
            free(key);
            FAIL(r, "out of memory");
            return NULL;
        }
    }
    if (v->keys)
        v->keys[v->count] = key;
    json *item = &v->items[v->count++];
    memset(item, 0, sizeof *item);
    return item;
}

static bool read_container(reader *r, json *v, bool object)
{
    char close = object ? '}' : ']';
    v->kind = object ? J_OBJECT : J_ARRAY;
    if (++r->depth > JSON_MAX_DEPTH)
        return FAIL(r, "nesting deeper than %d levels", JSON_MAX_DEPTH);
    advance(r);
    skip_space(r);
    if (peek(r) == close) {
        advance(r);
        r->depth--;
        return true;
    }
    for (;;) {
        char *key = NULL;
        if (object) {
            int line = r->line, col = r->col;
            if (peek(r) != '"')
                return FAIL(r, "expected a key in quotes");
            if (!read_string(r, &key))
                return false;
            for (size_t i = 0; i < v->count; i++)
                if (strcmp(v->keys[i], key) == 0) {
                    fail_at(r, line, col, "duplicate key \"%s\"", key);
                    free(key);
                    return false;
                }
            skip_space(r);
            if (peek(r) != ':') {
                free(key);
                return FAIL(r, "expected ':' after the key");
            }
            advance(r);
        }
        json *item = push_item(r, v, key);
        if (!item || !read_value(r, item))
            return false;
        skip_space(r);
        if (peek(r) == ',') {
            advance(r);
            skip_space(r);
            continue;
        }
        if (peek(r) == close) {
            advance(r);
            r->depth--;
            return true;
        }
        return FAIL(r, object ? "expected ',' or '}'" : "expected ',' or ']'");
    }
}

static bool read_value(reader *r, json *v)
{
    skip_space(r);
    v->line = r->line;
    v->col = r->col;
    int c = peek(r);
    switch (c) {
    case '{': return read_container(r, v, true);
    case '[': return read_container(r, v, false);
    case '"': v->kind = J_STRING; return read_string(r, &v->text);
    case 't': v->kind = J_BOOL; v->boolean = true; return read_word(r, "true");
    case 'f': v->kind = J_BOOL; return read_word(r, "false");
    case 'n': v->kind = J_NULL; return read_word(r, "null");
    case -1: return FAIL(r, "unexpected end of file (expected a value)");
    default:
        if (c == '-' || (c >= '0' && c <= '9'))
            return read_number(r, v);
        return FAIL(r, "unexpected character (expected a value)");
    }
}

/* -------------------------------------------------------- the scenario */

typedef struct {
    int64_t at;
    char value[NAME_MAX_BYTES];
    semo_value is;
} sensor_entry;

typedef struct {
    char name[NAME_MAX_BYTES];
    int64_t ms;
} service_entry;

typedef struct {
    int64_t at;
    double level;
} battery_entry;

/* A link fault that touches this robot: its messages to the peers marked in
 * `peers` (sent in [from, until)) are lost, or `by` ms late. */
typedef enum { LINK_LOST, LINK_DELAYED } link_effect;
typedef struct {
    link_effect effect;
    int64_t from, until, by;
    bool *peers; /* per peer of the program */
} link_fault;

typedef struct {
    int64_t next, every, until; /* every == 0: once, at `next` */
    bool done;
    char key[64];
    semo_value is;
} command_entry;

static struct {
    bool has_time_scale, has_duration;
    double time_scale;
    int64_t duration;
    sensor_entry *sensors;
    size_t sensor_count;
    service_entry *services;
    size_t service_count;
    /* "loops": per SDF/L loop path, the iteration whose exit task sets the exit flag. */
    service_entry *loops;
    size_t loop_count;
    command_entry *commands;
    size_t command_count;
    battery_entry *battery;
    size_t battery_count;
    link_fault *links;
    size_t link_count;
} g_sim;

static pthread_t g_operator;
static bool g_operator_started;

/* Type checks that report the value's own position. */
static bool want(reader *r, const json *v, json_kind kind, const char *what)
{
    if (v->kind == kind)
        return true;
    return fail_at(r, v->line, v->col, "expected %s", what);
}

static bool want_ms(reader *r, const json *v, const char *key, int64_t min, int64_t *out)
{
    if (v->kind != J_NUMBER || v->number < (double)min || v->number > (double)MAX_MS ||
        v->number != (double)(int64_t)v->number)
        return fail_at(r, v->line, v->col, "\"%s\" must be a whole number of milliseconds%s", key,
                       min > 0 ? " above 0" : "");
    *out = (int64_t)v->number;
    return true;
}

static bool want_name(reader *r, const json *v, const char *key, size_t cap, char *out)
{
    if (v->kind != J_STRING || v->text[0] == '\0' || strlen(v->text) >= cap)
        return fail_at(r, v->line, v->col, "\"%s\" must be a non-empty string shorter than %zu bytes", key, cap);
    memcpy(out, v->text, strlen(v->text) + 1);
    return true;
}

/* "is": a string, or a number taken as written; held as text, read as the
 * type of the value it is given to (a sensor's, a received key's). */
static bool want_value(reader *r, const json *v, semo_value *out)
{
    if ((v->kind != J_STRING && v->kind != J_NUMBER) || strlen(v->text) >= SEMO_TEXT_MAX)
        return fail_at(r, v->line, v->col, "\"is\" must be a string or number shorter than %d bytes", SEMO_TEXT_MAX);
    semo_value_set(out, v->text);
    return true;
}

static const json *member(const json *object, const char *key)
{
    for (size_t i = 0; i < object->count; i++)
        if (strcmp(object->keys[i], key) == 0)
            return &object->items[i];
    return NULL;
}

/* Every key of `object` must be one of `allowed` (a NULL-terminated list). */
static bool known_keys(reader *r, const json *object, const char *const *allowed, const char *where)
{
    for (size_t i = 0; i < object->count; i++) {
        bool known = false;
        for (const char *const *k = allowed; *k && !known; k++)
            known = strcmp(*k, object->keys[i]) == 0;
        if (!known)
            return fail_at(r, object->items[i].line, object->items[i].col, "unknown key \"%s\" in %s",
                           object->keys[i], where);
    }
    return true;
}

static bool require(reader *r, const json *object, const char *key, const json **out)
{
    *out = member(object, key);
    if (!*out)
        return fail_at(r, object->line, object->col, "missing \"%s\"", key);
    return true;
}

static bool grow(reader *r, void **array, size_t count, size_t size)
{
    void *grown = realloc(*array, (count + 1) * size);
    if (!grown) {
        return FAIL(r, "out of memory");
    }
    *array = grown;
    return true;
}

static bool read_sensor(reader *r, const json *v, bool keep)
{
    static const char *const keys[] = {"at", "value", "is", NULL};
    const json *at, *value, *is;
    sensor_entry e;
    if (!want(r, v, J_OBJECT, "a sensor entry {\"at\", \"value\", \"is\"}") ||
        !known_keys(r, v, keys, "a sensor entry") || !require(r, v, "at", &at) || !require(r, v, "value", &value) ||
        !require(r, v, "is", &is) || !want_ms(r, at, "at", 0, &e.at) ||
        !want_name(r, value, "value", sizeof e.value, e.value) || !want_value(r, is, &e.is))
        return false;
    if (!keep)
        return true;
    if (!grow(r, (void **)&g_sim.sensors, g_sim.sensor_count, sizeof e))
        return false;
    g_sim.sensors[g_sim.sensor_count++] = e;
    return true;
}

/* "battery": levels {"at", "level"} in time order (the sensor value BATTERY). */
static bool read_battery(reader *r, const json *v, bool keep)
{
    static const char *const keys[] = {"at", "level", NULL};
    if (!want(r, v, J_ARRAY, "an array of battery levels {\"at\", \"level\"}"))
        return false;
    int64_t last = -1;
    for (size_t i = 0; i < v->count; i++) {
        const json *entry = &v->items[i], *at, *level;
        battery_entry e;
        if (!want(r, entry, J_OBJECT, "a battery level {\"at\", \"level\"}") ||
            !known_keys(r, entry, keys, "a battery level") || !require(r, entry, "at", &at) ||
            !require(r, entry, "level", &level) || !want_ms(r, at, "at", 0, &e.at))
            return false;
        if (e.at <= last)
            return fail_at(r, at->line, at->col, "battery levels must be in time order");
        last = e.at;
        if (level->kind != J_NUMBER)
            return fail_at(r, level->line, level->col, "\"level\" must be a number");
        /* Its rounding must fit a long long (the simulator's bound too). */
        if (level->number > MAX_LEVEL || level->number < -MAX_LEVEL)
            return fail_at(r, level->line, level->col, "\"level\" must be between -1e15 and 1e15");
        e.level = level->number;
        if (keep) {
            if (!grow(r, (void **)&g_sim.battery, g_sim.battery_count, sizeof e))
                return false;
            g_sim.battery[g_sim.battery_count++] = e;
        }
    }
    return true;
}

static bool read_robot(reader *r, const json *v, bool keep)
{
    static const char *const keys[] = {"sensors", "services", "battery", "loops", NULL};
    if (!want(r, v, J_OBJECT, "a robot {\"sensors\": [...], \"services\": {...}, \"battery\": [...], \"loops\": {...}}") ||
        !known_keys(r, v, keys, "a robot"))
        return false;
    const json *sensors = member(v, "sensors"), *services = member(v, "services"), *battery = member(v, "battery");
    const json *loops = member(v, "loops");
    if (loops) {
        if (!want(r, loops, J_OBJECT, "an object of loop exits {\"Converge\": 3}"))
            return false;
        for (size_t i = 0; i < loops->count; i++) {
            service_entry e;
            const json *n = &loops->items[i];
            if (strlen(loops->keys[i]) >= sizeof e.name)
                return fail_at(r, n->line, n->col, "loop path too long");
            memcpy(e.name, loops->keys[i], strlen(loops->keys[i]) + 1);
            if (n->kind != J_NUMBER || n->number < 1 || n->number > 1e9 || n->number != (double)(int64_t)n->number)
                return fail_at(r, n->line, n->col, "\"%s\" must be a whole number of iterations, 1 or more", loops->keys[i]);
            e.ms = (int64_t)n->number;
            if (keep) {
                if (!grow(r, (void **)&g_sim.loops, g_sim.loop_count, sizeof e))
                    return false;
                g_sim.loops[g_sim.loop_count++] = e;
            }
        }
    }
    if (battery && !read_battery(r, battery, keep))
        return false;
    if (sensors) {
        if (!want(r, sensors, J_ARRAY, "an array of sensor entries"))
            return false;
        for (size_t i = 0; i < sensors->count; i++)
            if (!read_sensor(r, &sensors->items[i], keep))
                return false;
    }
    if (services) {
        if (!want(r, services, J_OBJECT, "an object of service durations {\"move\": 300}"))
            return false;
        for (size_t i = 0; i < services->count; i++) {
            service_entry e;
            if (strlen(services->keys[i]) >= sizeof e.name)
                return fail_at(r, services->items[i].line, services->items[i].col, "service name too long");
            memcpy(e.name, services->keys[i], strlen(services->keys[i]) + 1);
            if (!want_ms(r, &services->items[i], services->keys[i], 0, &e.ms))
                return false;
            if (keep) {
                if (!grow(r, (void **)&g_sim.services, g_sim.service_count, sizeof e))
                    return false;
                g_sim.services[g_sim.service_count++] = e;
            }
        }
    }
    return true;
}

static bool read_command(reader *r, const json *v, const semo_program_desc *program)
{
    static const char *const keys[] = {"at", "every", "from", "until", "to", "value", "is", NULL};
    const json *to, *value, *is;
    const json *at = member(v, "at"), *every = member(v, "every");
    const json *from = member(v, "from"), *until = member(v, "until");
    command_entry e = {.until = MAX_MS};
    char to_name[64], name[NAME_MAX_BYTES];
    if (!want(r, v, J_OBJECT, "an operator command {\"at\"|\"every\", \"to\", \"value\", \"is\"}") ||
        !known_keys(r, v, keys, "an operator command") || !require(r, v, "to", &to) ||
        !require(r, v, "value", &value) || !require(r, v, "is", &is) ||
        !want_name(r, to, "to", sizeof to_name, to_name) || !want_name(r, value, "value", sizeof name, name) ||
        !want_value(r, is, &e.is))
        return false;
    if (!at == !every)
        return fail_at(r, v->line, v->col, "an operator command needs either \"at\" or \"every\"");
    if (at && (from || until))
        return fail_at(r, v->line, v->col, "\"from\" and \"until\" go with \"every\", not \"at\"");
    if (at && !want_ms(r, at, "at", 0, &e.next))
        return false;
    if (every && (!want_ms(r, every, "every", 1, &e.every) || (from && !want_ms(r, from, "from", 0, &e.next)) ||
                  (until && !want_ms(r, until, "until", 0, &e.until))))
        return false;
    if (strcmp(to_name, program->robot) != 0 && strcmp(to_name, program->team) != 0)
        return true; /* for another robot */
    if (e.next > e.until)
        return true; /* a repetition that never starts */
    snprintf(e.key, sizeof e.key, "USER.%s", name);
    if (!grow(r, (void **)&g_sim.commands, g_sim.command_count, sizeof e))
        return false;
    g_sim.commands[g_sim.command_count++] = e;
    return true;
}

/* A robot a fault names that is not among this robot's peers. */
#define NOT_A_PEER SIZE_MAX

/* The peer index of robot `v`, or NOT_A_PEER: the program knows only its
 * peers (the robots it sends to or hears from), so a robot it does not know
 * is one whose messages it never takes part in; as with the "robots" of
 * others, whether the name is in the mission is `semo simulate`'s check
 * (scenario.rs), which reads the scenario with the whole fleet. */
static bool want_robot(reader *r, const json *v, const char *key, const semo_program_desc *program, size_t *out)
{
    char name[64];
    if (!want_name(r, v, key, NAME_MAX_BYTES, name))
        return false;
    *out = NOT_A_PEER;
    for (size_t i = 0; i < program->peer_count; i++)
        if (strcmp(program->peers[i].robot, name) == 0)
            *out = i;
    return true;
}

static bool want_interval(reader *r, const json *v, int64_t *from, int64_t *until)
{
    const json *f, *u;
    if (!require(r, v, "from", &f) || !want_ms(r, f, "from", 0, from) || !require(r, v, "until", &u) ||
        !want_ms(r, u, "until", 0, until))
        return false;
    if (*until <= *from)
        return fail_at(r, u->line, u->col, "\"until\" must be after \"from\"");
    return true;
}

/* One fault. Only link faults touching this robot are kept, as the peers
 * whose messages from it they affect (the simulator's Sim::link). */
static bool read_fault(reader *r, const json *v, const semo_program_desc *program)
{
    static const char *const keys[] = {"at", "kill", "restart", "drop", "delay", "by", "partition", "from", "until",
                                       NULL};
    static const char *const kinds[] = {"kill", "restart", "drop", "delay", "partition"};
    if (!want(r, v, J_OBJECT, "a fault {\"kill\"|\"restart\"|\"drop\"|\"delay\"|\"partition\", ...}") ||
        !known_keys(r, v, keys, "a fault"))
        return false;
    int kind = -1, given = 0;
    for (int k = 0; k < 5; k++)
        if (member(v, kinds[k])) {
            kind = k;
            given++;
        }
    if (given != 1)
        return fail_at(r, v->line, v->col,
                       "a fault is exactly one of \"kill\", \"restart\", \"drop\", \"delay\", \"partition\"");
    const json *what = member(v, kinds[kind]), *at;
    size_t robot;
    int64_t ms;
    if (kind <= 1) /* kill, restart: done to the process from outside */
        return want_robot(r, what, kinds[kind], program, &robot) && require(r, v, "at", &at) &&
               want_ms(r, at, "at", 0, &ms);
    link_fault f = {.effect = kind == 3 ? LINK_DELAYED : LINK_LOST};
    if (!want_interval(r, v, &f.from, &f.until))
        return false;
    if (kind == 3) {
        const json *by;
        if (!require(r, v, "by", &by) || !want_ms(r, by, "by", 0, &f.by))
            return false;
    }
    f.peers = calloc(program->peer_count ? program->peer_count : 1, sizeof *f.peers);
    if (!f.peers)
        return FAIL(r, "out of memory");
    bool touches = false;
    if (kind != 4) { /* drop, delay: between two robots, both directions */
        size_t a, b;
        bool ok = want(r, what, J_ARRAY, "two robot names") &&
                  (what->count == 2 || fail_at(r, what->line, what->col, "\"%s\" must name two robots", kinds[kind])) &&
                  want_robot(r, &what->items[0], kinds[kind], program, &a) &&
                  want_robot(r, &what->items[1], kinds[kind], program, &b);
        if (!ok) {
            free(f.peers);
            return false;
        }
        size_t other = a == program->self ? b : a;
        if ((a == program->self || b == program->self) && other != NOT_A_PEER) {
            f.peers[other] = true;
            touches = true;
        }
    } else { /* partition: robots of different groups (no group is one more) cannot talk */
        long *group = malloc((program->peer_count ? program->peer_count : 1) * sizeof *group);
        bool out_of_memory = group == NULL;
        bool ok = !out_of_memory && want(r, what, J_ARRAY, "an array of groups of robot names");
        for (size_t i = 0; ok && i < program->peer_count; i++)
            group[i] = -1;
        for (size_t g = 0; ok && g < what->count; g++) {
            const json *members = &what->items[g];
            ok = want(r, members, J_ARRAY, "a group: an array of robot names");
            for (size_t m = 0; ok && m < members->count; m++) {
                size_t peer;
                ok = want_robot(r, &members->items[m], "partition", program, &peer);
                if (ok && peer != NOT_A_PEER && group[peer] < 0)
                    group[peer] = (long)g;
            }
        }
        for (size_t i = 0; ok && i < program->peer_count; i++)
            if (i != program->self && group[i] != group[program->self])
                f.peers[i] = touches = true;
        free(group);
        if (!ok) {
            free(f.peers);
            return out_of_memory ? FAIL(r, "out of memory") : false;
        }
    }
    if (!touches || !grow(r, (void **)&g_sim.links, g_sim.link_count, sizeof f)) {
        free(f.peers);
        return !touches;
    }
    g_sim.links[g_sim.link_count++] = f;
    return true;
}

static bool read_scenario(reader *r, const json *root, const semo_program_desc *program)
{
    /* The shared schema (docs/scenario-and-trace.md): "version", "network"
     * and "expect" are the simulator's (`semo simulate`); they are accepted
     * here and left to it. */
    static const char *const keys[] = {"version", "time_scale", "duration", "robots", "operator",
                                       "network", "faults", "expect", NULL};
    if (!want(r, root, J_OBJECT, "a scenario object {\"robots\": ..., \"operator\": ...}") ||
        !known_keys(r, root, keys, "the scenario"))
        return false;
    const json *scale = member(root, "time_scale"), *duration = member(root, "duration");
    const json *robots = member(root, "robots"), *commands = member(root, "operator"), *faults = member(root, "faults");
    if (scale) {
        if (scale->kind != J_NUMBER || !(scale->number >= SEMO_TIME_SCALE_MIN && scale->number <= SEMO_TIME_SCALE_MAX))
            return fail_at(r, scale->line, scale->col,
                           "\"time_scale\" must be a positive number from 0.000001 (a million times faster) to 1000000");
        g_sim.time_scale = scale->number;
        g_sim.has_time_scale = true;
    }
    if (duration) {
        if (!want_ms(r, duration, "duration", 0, &g_sim.duration))
            return false;
        g_sim.has_duration = true;
    }
    if (robots) {
        if (!want(r, robots, J_OBJECT, "an object of robots {\"name\": {...}}"))
            return false;
        /* Robots of other missions or not in this one are checked, then ignored. */
        for (size_t i = 0; i < robots->count; i++)
            if (!read_robot(r, &robots->items[i], strcmp(robots->keys[i], program->robot) == 0))
                return false;
    }
    if (commands) {
        if (!want(r, commands, J_ARRAY, "an array of operator commands"))
            return false;
        for (size_t i = 0; i < commands->count; i++)
            if (!read_command(r, &commands->items[i], program))
                return false;
    }
    if (faults) {
        if (!want(r, faults, J_ARRAY, "an array of faults"))
            return false;
        for (size_t i = 0; i < faults->count; i++)
            if (!read_fault(r, &faults->items[i], program))
                return false;
    }
    return true;
}

static char *read_file(const char *path, size_t *len, char *why, size_t why_cap)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(why, why_cap, "%s", strerror(errno));
        return NULL;
    }
    char *data = NULL;
    size_t cap = 0, n = 0;
    for (;;) {
        if (n == cap) {
            cap = cap ? cap * 2 : 4096;
            char *grown = cap <= (size_t)SCENARIO_MAX_BYTES ? realloc(data, cap + 1) : NULL;
            if (!grown) {
                snprintf(why, why_cap, "larger than %ld bytes or out of memory", SCENARIO_MAX_BYTES);
                free(data);
                fclose(f);
                return NULL;
            }
            data = grown;
        }
        size_t got = fread(data + n, 1, cap - n, f);
        n += got;
        if (got == 0)
            break;
    }
    bool failed = ferror(f);
    fclose(f);
    if (failed) {
        snprintf(why, why_cap, "read error");
        free(data);
        return NULL;
    }
    data[n] = '\0';
    *len = n;
    return data;
}

int semo__sim_load(const char *path, const semo_program_desc *program)
{
    char why[128];
    size_t len = 0;
    char *text = read_file(path, &len, why, sizeof why);
    if (!text) {
        fprintf(stderr, "scenario %s: cannot read: %s\n", path, why);
        return -1;
    }
    reader r = {.s = text, .len = len, .line = 1, .col = 1};
    json root = {0};
    bool ok = read_value(&r, &root);
    if (ok) {
        skip_space(&r);
        if (r.pos < r.len)
            ok = FAIL(&r, "unexpected text after the scenario object");
    }
    ok = ok && read_scenario(&r, &root, program);
    json_free(&root);
    free(text);
    if (!ok) {
        fprintf(stderr, "scenario %s:%d:%d: %s\n", path, r.error_line, r.error_col, r.error);
        semo__sim_free();
        return -1;
    }
    return 0;
}

bool semo__sim_time_scale(double *out)
{
    if (g_sim.has_time_scale)
        *out = g_sim.time_scale;
    return g_sim.has_time_scale;
}

bool semo__sim_duration(int64_t *out)
{
    if (g_sim.has_duration)
        *out = g_sim.duration;
    return g_sim.has_duration;
}

bool semo__sim_has_link_faults(void)
{
    return g_sim.link_count > 0;
}

void semo__sim_free(void)
{
    free(g_sim.sensors);
    free(g_sim.services);
    free(g_sim.loops);
    free(g_sim.commands);
    free(g_sim.battery);
    for (size_t i = 0; i < g_sim.link_count; i++)
        free(g_sim.links[i].peers);
    free(g_sim.links);
    memset(&g_sim, 0, sizeof g_sim);
}

/* ------------------------------------------------- the running scenario */

/* The tables are read-only once tasks run; only this thread touches the
 * commands' `next` and `done`. */
static void *operator_thread(void *arg)
{
    (void)arg;
    for (;;) {
        command_entry *due = NULL;
        for (size_t i = 0; i < g_sim.command_count; i++) {
            command_entry *c = &g_sim.commands[i];
            if (!c->done && (!due || c->next < due->next))
                due = c;
        }
        if (!due || !semo__wait_until(due->next))
            return NULL;
        semo_message m = {.kind = SEMO_MSG_SEND, .from_team = "USER", .from_robot = "USER", .value = due->is};
        memcpy(m.key, due->key, sizeof m.key);
        semo__deliver(&m);
        if (due->every > 0 && due->next + due->every <= due->until)
            due->next += due->every;
        else
            due->done = true;
    }
}

bool semo__sim_link(size_t peer, int64_t *delay_ms)
{
    int64_t now = semo_now_ms();
    *delay_ms = 0;
    for (size_t i = 0; i < g_sim.link_count; i++) {
        const link_fault *f = &g_sim.links[i];
        if (!f->peers[peer] || now < f->from || now >= f->until)
            continue;
        if (f->effect == LINK_LOST)
            return false;
        *delay_ms += f->by;
    }
    return true;
}

/* Datagrams held back by a delay fault, sent by one thread at their time. */
typedef struct late_datagram {
    struct late_datagram *next;
    int64_t due;
    size_t peer, len;
    unsigned char data[];
} late_datagram;

static struct {
    pthread_mutex_t lock;
    pthread_cond_t changed;
    late_datagram *queue; /* unordered; a delay fault holds few at a time */
    const semo_transport *transport;
    bool stopping, started;
    pthread_t thread;
} g_late = {.lock = PTHREAD_MUTEX_INITIALIZER};

static bool has_delays(void)
{
    for (size_t i = 0; i < g_sim.link_count; i++)
        if (g_sim.links[i].effect == LINK_DELAYED)
            return true;
    return false;
}

void semo__sim_send_later(const semo_transport *transport, size_t peer, const void *data, size_t len,
                          int64_t delay_ms)
{
    late_datagram *d = malloc(sizeof *d + len);
    if (!d) {
        semo_trace("comm_error", "reason", "out of memory for a delayed message", NULL);
        return;
    }
    d->due = semo_now_ms() + delay_ms;
    d->peer = peer;
    d->len = len;
    memcpy(d->data, data, len);
    pthread_mutex_lock(&g_late.lock);
    g_late.transport = transport;
    d->next = g_late.queue;
    g_late.queue = d;
    semo__cond_signal(&g_late.changed);
    pthread_mutex_unlock(&g_late.lock);
}

static void *late_thread(void *arg)
{
    (void)arg;
    pthread_mutex_lock(&g_late.lock);
    while (!g_late.stopping) {
        /* The earliest due; of equals the one sent first (the queue is
         * newest first), so that delayed messages keep their order. */
        late_datagram **first = NULL;
        for (late_datagram **d = &g_late.queue; *d; d = &(*d)->next)
            if (!first || (*d)->due <= (*first)->due)
                first = d;
        if (!first) {
            semo__cond_wait_until(&g_late.changed, &g_late.lock, -1);
            continue;
        }
        if (semo_now_ms() < (*first)->due) {
            semo__cond_wait_until(&g_late.changed, &g_late.lock, (*first)->due);
            continue;
        }
        late_datagram *due = *first;
        *first = due->next;
        const semo_transport *transport = g_late.transport;
        pthread_mutex_unlock(&g_late.lock);
        if (transport->send(due->peer, due->data, due->len) != 0)
            semo_trace("comm_error", "to", semo_program()->peers[due->peer].robot, NULL);
        free(due);
        pthread_mutex_lock(&g_late.lock);
    }
    while (g_late.queue) { /* not due before the program stopped */
        late_datagram *d = g_late.queue;
        g_late.queue = d->next;
        free(d);
    }
    pthread_mutex_unlock(&g_late.lock);
    return NULL;
}

int semo__sim_start(void)
{
    if (has_delays()) {
        semo__cond_init(&g_late.changed);
        g_late.stopping = false;
        if (!semo__start_thread(&g_late.thread, late_thread, NULL)) {
            fprintf(stderr, "semo runtime: cannot start the simulated network\n");
            pthread_cond_destroy(&g_late.changed);
            return -1;
        }
        g_late.started = true;
    }
    if (g_sim.command_count == 0)
        return 0;
    if (!semo__start_thread(&g_operator, operator_thread, NULL)) {
        fprintf(stderr, "semo runtime: cannot start the simulated operator\n");
        return -1;
    }
    g_operator_started = true;
    return 0;
}

void semo__sim_stop(void)
{
    if (g_operator_started)
        pthread_join(g_operator, NULL);
    g_operator_started = false;
    if (g_late.started) {
        pthread_mutex_lock(&g_late.lock);
        g_late.stopping = true;
        semo__cond_signal(&g_late.changed);
        pthread_mutex_unlock(&g_late.lock);
        pthread_join(g_late.thread, NULL);
        pthread_cond_destroy(&g_late.changed);
    }
    g_late.started = false;
}

/* The battery level at `t`: linear between the scenario's points, the first
 * before them and the last after them (the simulator's battery_level, the
 * same operations in the same order). */
static double battery_level(int64_t t)
{
    const battery_entry *b = g_sim.battery;
    if (t <= b[0].at)
        return b[0].level;
    for (size_t i = 1; i < g_sim.battery_count; i++)
        if (t <= b[i].at)
            return b[i - 1].level + (b[i].level - b[i - 1].level) * (double)(t - b[i - 1].at) / (double)(b[i].at - b[i - 1].at);
    return b[g_sim.battery_count - 1].level;
}

/* Rust's f64::round (halves away from zero) without libm: doubles of 2^52
 * and more are whole already. */
static double round_half_away(double x)
{
    if (!(x > -4503599627370496.0 && x < 4503599627370496.0))
        return x;
    double whole = (double)(long long)x; /* toward zero; the fraction is exact */
    if (x - whole >= 0.5)
        return whole + 1;
    if (whole - x >= 0.5)
        return whole - 1;
    return whole;
}

bool semo_sim_sensor(const char *value, semo_type type, semo_value *out)
{
    const sensor_entry *latest = NULL;
    int64_t now = semo_now_ms();
    for (size_t i = 0; value && i < g_sim.sensor_count; i++) {
        const sensor_entry *e = &g_sim.sensors[i];
        if (e->at <= now && strcmp(e->value, value) == 0 && (!latest || e->at >= latest->at))
            latest = e;
    }
    semo_value read;
    if (latest)
        return semo_value_parse(out ? out : &read, type, latest->is.text);
    if (value && strcmp(value, "BATTERY") == 0 && g_sim.battery_count > 0) {
        char text[400]; /* "%.0f" of any double fits */
        snprintf(text, sizeof text, "%.0f", round_half_away(battery_level(now)));
        return semo_value_parse(out ? out : &read, type, text);
    }
    return false;
}

bool semo_sim_battery(long long *level)
{
    if (g_sim.battery_count == 0)
        return false;
    if (level)
        *level = (long long)round_half_away(battery_level(semo_now_ms()));
    return true;
}

void semo_sim_actuate(const char *task, const semo_value *command)
{
    semo_trace_value("actuate", "value", command ? command : SEMO_LIT(""), "task", task, NULL);
}

int64_t semo_sim_service_ms(const char *service)
{
    for (size_t i = 0; service && i < g_sim.service_count; i++)
        if (strcmp(g_sim.services[i].name, service) == 0)
            return g_sim.services[i].ms;
    return DEFAULT_SERVICE_MS;
}

int64_t semo_sim_loop_exit(const char *loop)
{
    for (size_t i = 0; loop && i < g_sim.loop_count; i++)
        if (strcmp(g_sim.loops[i].name, loop) == 0)
            return g_sim.loops[i].ms;
    return 0;
}

#else
/* ISO C wants at least one declaration in a translation unit. */
typedef int semo_sim_disabled;
#endif /* SEMO_SIM */
