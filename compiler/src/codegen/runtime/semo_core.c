/* semo_core.c: the portable core of the SeMo runtime, shared by every
 * platform layer (POSIX threads, static schedule).
 *
 * No POSIX, no stdio, no heap: values, the trace line format and integer
 * formatting. Platforms give the bytes of a trace line a destination (a file,
 * a UART) through a `semo__sink`.
 */
#include "semo_internal.h"

#include <stdarg.h>
#include <string.h>

/* ----------------------------------------------------------------- numbers */

size_t semo__format_i64(char *out, int64_t n)
{
    /* Digits are produced from the magnitude as unsigned, so INT64_MIN works. */
    uint64_t magnitude = n < 0 ? (uint64_t)0 - (uint64_t)n : (uint64_t)n;
    char digits[20];
    size_t count = 0;
    do {
        digits[count++] = (char)('0' + magnitude % 10);
        magnitude /= 10;
    } while (magnitude > 0);
    size_t len = 0;
    if (n < 0)
        out[len++] = '-';
    while (count > 0)
        out[len++] = digits[--count];
    out[len] = '\0';
    return len;
}

static bool is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static bool same_word(const char *s, const char *word)
{
    for (; *word; s++, word++)
        if ((*s | 0x20) != *word)
            return false;
    return *s == '\0';
}

/* The whole text as a number, in the grammar the simulator reads (Rust's
 * f64): [+-] then digits with an optional fraction (".5" and "5." too) and
 * an optional exponent, or "inf"/"infinity". "5,5", " 5", "0x10" and "" are
 * not numbers. Written here rather than with strtod, which needs locale
 * tables and, in newlib, a heap. */
static bool parse_number(const char *s, double *out)
{
    bool negative = *s == '-';
    if (*s == '-' || *s == '+')
        s++;
    if (same_word(s, "inf") || same_word(s, "infinity")) {
        *out = negative ? -__builtin_inf() : __builtin_inf();
        return true;
    }
    uint64_t mantissa = 0;
    int exponent = 0, digits = 0;
    for (; is_digit(*s); s++, digits++) {
        if (mantissa < 100000000000000000ull)
            mantissa = mantissa * 10 + (uint64_t)(*s - '0');
        else
            exponent++;
    }
    if (*s == '.') {
        for (s++; is_digit(*s); s++, digits++) {
            if (mantissa < 100000000000000000ull) {
                mantissa = mantissa * 10 + (uint64_t)(*s - '0');
                exponent--;
            }
        }
    }
    if (digits == 0)
        return false;
    if (*s == 'e' || *s == 'E') {
        s++;
        bool exp_negative = *s == '-';
        if (*s == '-' || *s == '+')
            s++;
        if (!is_digit(*s))
            return false;
        int e = 0;
        for (; is_digit(*s); s++)
            if (e < 100000)
                e = e * 10 + (*s - '0');
        exponent += exp_negative ? -e : e;
    }
    if (*s != '\0')
        return false;
    double value = (double)mantissa;
    /* Powers of ten up to 1e22 are exact doubles: most values convert exactly. */
    double scale = 1.0;
    int e = exponent < 0 ? -exponent : exponent;
    double power = 10.0;
    for (; e > 0 && value != 0; e >>= 1, power *= power)
        if (e & 1)
            scale *= power;
    value = exponent < 0 ? value / scale : value * scale;
    *out = negative ? -value : value;
    return true;
}

/* ------------------------------------------------------------------ values */

void semo_value_set(semo_value *v, const char *text)
{
    if (!text)
        text = "";
    size_t n = strlen(text);
    if (n >= SEMO_VALUE_MAX) {
        n = SEMO_VALUE_MAX - 1;
        /* Never cut a UTF-8 character in half. */
        while (n > 0 && ((unsigned char)text[n] & 0xC0) == 0x80)
            n--;
    }
    memmove(v->text, text, n);
    v->text[n] = '\0';
}

void semo_value_set_int(semo_value *v, long long n)
{
    semo__format_i64(v->text, (int64_t)n);
}

int semo_value_compare(const semo_value *a, const semo_value *b)
{
    double x, y;
    if (parse_number(a->text, &x) && parse_number(b->text, &y))
        return (x > y) - (x < y);
    int c = strcmp(a->text, b->text);
    return (c > 0) - (c < 0);
}

bool semo_value_numeric(const semo_value *v)
{
    double x;
    return parse_number(v->text, &x);
}

bool semo_value_truthy(const semo_value *v)
{
    double x;
    if (strcmp(v->text, "true") == 0)
        return true;
    return parse_number(v->text, &x) && x != 0;
}

/* ------------------------------------------------------------------ traces */

/* Length of the valid UTF-8 sequence at `s`, or 0 (overlong, surrogate,
 * beyond U+10FFFF, truncated). */
static size_t utf8_sequence(const unsigned char *s)
{
    unsigned c = s[0];
    size_t n;
    unsigned min, cp;
    if (c >= 0xC2 && c <= 0xDF) {
        n = 2, min = 0x80, cp = c & 0x1F;
    } else if (c >= 0xE0 && c <= 0xEF) {
        n = 3, min = 0x800, cp = c & 0x0F;
    } else if (c >= 0xF0 && c <= 0xF4) {
        n = 4, min = 0x10000, cp = c & 0x07;
    } else {
        return 0;
    }
    for (size_t i = 1; i < n; i++) {
        if ((s[i] & 0xC0) != 0x80)
            return 0;
        cp = (cp << 6) | (s[i] & 0x3F);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
        return 0;
    return n;
}

static void put_text(const semo__sink *sink, const char *text)
{
    sink->put(sink->ctx, text, strlen(text));
}

/* A JSON string: control characters escaped, invalid UTF-8 as U+FFFD so
 * that every line parses. */
static void put_json_string(const semo__sink *sink, const char *text)
{
    static const char hex[] = "0123456789abcdef";
    const unsigned char *s = (const unsigned char *)(text ? text : "");
    put_text(sink, "\"");
    while (*s) {
        /* A run of characters that need no escape goes out at once. */
        size_t plain = 0;
        while (s[plain] >= 0x20 && s[plain] < 0x80 && s[plain] != '"' && s[plain] != '\\')
            plain++;
        if (plain > 0) {
            sink->put(sink->ctx, (const char *)s, plain);
            s += plain;
            continue;
        }
        unsigned c = *s;
        if (c == '"' || c == '\\') {
            char escaped[2] = {'\\', (char)c};
            sink->put(sink->ctx, escaped, 2);
            s++;
        } else if (c < 0x20) {
            switch (c) {
            case '\n': put_text(sink, "\\n"); break;
            case '\r': put_text(sink, "\\r"); break;
            case '\t': put_text(sink, "\\t"); break;
            default: {
                char escaped[6] = {'\\', 'u', '0', '0', hex[c >> 4], hex[c & 15]};
                sink->put(sink->ctx, escaped, 6);
                break;
            }
            }
            s++;
        } else {
            size_t n = utf8_sequence(s);
            if (n == 0) {
                put_text(sink, "\\ufffd");
                s++;
            } else {
                sink->put(sink->ctx, (const char *)s, n);
                s += n;
            }
        }
    }
    put_text(sink, "\"");
}

void semo__trace_line(const semo__sink *sink, int64_t t, const char *robot, const char *event, va_list args)
{
    char number[21];
    put_text(sink, "{\"t\":");
    semo__format_i64(number, t);
    put_text(sink, number);
    put_text(sink, ",\"robot\":");
    put_json_string(sink, robot ? robot : "");
    put_text(sink, ",\"event\":");
    put_json_string(sink, event);
    const char *key;
    while ((key = va_arg(args, const char *)) != NULL) {
        const char *value = va_arg(args, const char *);
        put_text(sink, ",");
        put_json_string(sink, key);
        put_text(sink, ":");
        if (!value) {
            /* An odd list: the NULL meant as the end came as a value. */
            put_text(sink, "null");
            break;
        }
        put_json_string(sink, value);
    }
    put_text(sink, "}\n");
}
