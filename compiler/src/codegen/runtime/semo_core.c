/* semo_core.c: the portable core of the SeMo runtime, shared by every
 * platform layer (POSIX threads, static schedule).
 *
 * No POSIX, no stdio, no heap: values, the trace line format, integer
 * formatting, channels (ports), the inbox of messages and what a send does
 * before the transport. Platforms give the bytes of a trace line a
 * destination (a file, a UART) through a `semo__sink`, and the queues their
 * storage, lock and wake-ups through the hooks of semo_internal.h.
 */
#include "semo_internal.h"

#include <stdarg.h>
#include <stdatomic.h>
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

#ifndef SEMO_NO_REALS
/* Reals print from their exact binary value, as `refine::value::format_real`
 * does (the same digits, so traces agree to the byte): below 1e15 in
 * magnitude, rounded half up to six decimals with trailing zeros dropped
 * but one kept (`2.0`, `0.125`, `0.333333`); from 1e15 on, the first fifteen
 * significant digits rounded half up and an exponent (`1.5e20` is
 * `150000000000000e6`); a set sign bit is a `-` (`-0.0`); `inf`, `-inf` and
 * `nan` otherwise (never in JSON: `put_json_value` writes those as null).
 * Integer arithmetic only, on a few 32-bit words: no printf (newlib-nano's
 * has no floating point), no libm, no 128-bit integers (32-bit targets). */

/* A natural number below 2^1120, least significant word first: room for a
 * double's integer part (below 2^1024) and for a subnormal fraction's bits
 * times 10^7 (below 2^1098). */
#define BIG_WORDS 35
typedef struct {
    uint32_t word[BIG_WORDS];
    size_t len; /* words in use; the top one is not zero */
} big;

static void big_set(big *b, uint64_t n)
{
    b->word[0] = (uint32_t)n;
    b->word[1] = (uint32_t)(n >> 32);
    b->len = n == 0 ? 0 : n >> 32 ? 2 : 1;
}

static void big_trim(big *b)
{
    while (b->len > 0 && b->word[b->len - 1] == 0)
        b->len--;
}

static void big_mul_small(big *b, uint32_t factor)
{
    uint64_t carry = 0;
    for (size_t i = 0; i < b->len; i++) {
        carry += (uint64_t)b->word[i] * factor;
        b->word[i] = (uint32_t)carry;
        carry >>= 32;
    }
    if (carry)
        b->word[b->len++] = (uint32_t)carry;
}

/* b /= divisor, rounded down. */
static void big_div_small(big *b, uint32_t divisor)
{
    uint64_t rest = 0;
    for (size_t i = b->len; i-- > 0;) {
        rest = rest << 32 | b->word[i];
        b->word[i] = (uint32_t)(rest / divisor);
        rest %= divisor;
    }
    big_trim(b);
}

static void big_shift_left(big *b, unsigned bits)
{
    size_t words = bits / 32, len = b->len;
    unsigned rest = bits % 32;
    if (len == 0)
        return;
    b->word[len + words] = 0;
    for (size_t i = len; i-- > 0;) {
        b->word[i + words + 1] |= rest ? b->word[i] >> (32 - rest) : 0;
        b->word[i + words] = b->word[i] << rest;
    }
    for (size_t i = 0; i < words; i++)
        b->word[i] = 0;
    b->len = len + words + 1;
    big_trim(b);
}

static void big_shift_right(big *b, unsigned bits)
{
    size_t words = bits / 32;
    unsigned rest = bits % 32;
    if (words >= b->len) {
        b->len = 0;
        return;
    }
    size_t len = b->len - words;
    for (size_t i = 0; i < len; i++) {
        uint32_t high = i + words + 1 < b->len && rest ? b->word[i + words + 1] << (32 - rest) : 0;
        b->word[i] = b->word[i + words] >> rest | high;
    }
    b->len = len;
    big_trim(b);
}

/* The value, when it is below 2^64. */
static bool big_small(const big *b, uint64_t *out)
{
    if (b->len > 2)
        return false;
    *out = (b->len > 1 ? (uint64_t)b->word[1] << 32 : 0) | (b->len > 0 ? b->word[0] : 0);
    return true;
}

static size_t put_text_at(char *out, const char *text)
{
    size_t len = strlen(text);
    memcpy(out, text, len + 1);
    return len;
}

/* `digits` e `exponent`: the first fifteen significant digits of the
 * integer `whole` (at least 10^15) rounded half up. */
static size_t format_scientific(char *out, big *whole)
{
    const uint64_t sixteen_digits = 10000000000000000ull;
    int exponent = 0;
    uint64_t top;
    /* Four words or more is at least 2^96 > 10^25: nine digits can go at once. */
    while (whole->len >= 4) {
        big_div_small(whole, 1000000000u);
        exponent += 9;
    }
    while (!big_small(whole, &top) || top >= sixteen_digits) {
        big_div_small(whole, 10);
        exponent++;
    }
    /* `top` has sixteen digits: the last one rounds. */
    uint64_t digits = top / 10 + (top % 10 >= 5);
    exponent++;
    if (digits == 1000000000000000ull) {
        digits /= 10;
        exponent++;
    }
    size_t len = semo__format_i64(out, (int64_t)digits);
    out[len++] = 'e';
    return len + semo__format_i64(out + len, exponent);
}

/* `whole`.`fraction`: the real `mantissa` / 2^`shift` (below 10^15), rounded
 * half up to six decimals, trailing zeros dropped but one. */
static size_t format_fixed(char *out, uint64_t mantissa, unsigned shift)
{
    uint64_t whole = shift < 64 ? mantissa >> shift : 0;
    uint64_t bits = shift < 64 ? mantissa & ((1ull << shift) - 1) : mantissa;
    /* Seven decimals of bits / 2^shift, cut: the seventh rounds. */
    big seven;
    big_set(&seven, bits);
    big_mul_small(&seven, 10000000u);
    big_shift_right(&seven, shift);
    uint64_t decimals = 0;
    big_small(&seven, &decimals); /* below 10^7: always small */
    int64_t fraction = (int64_t)(decimals / 10 + (decimals % 10 >= 5));
    if (fraction == 1000000) {
        fraction = 0;
        whole++;
    }
    size_t len = semo__format_i64(out, (int64_t)whole);
    out[len++] = '.';
    int digits = 6;
    while (digits > 1 && fraction % 10 == 0) {
        fraction /= 10;
        digits--;
    }
    for (int i = digits - 1; i >= 0; i--, fraction /= 10)
        out[len + (size_t)i] = (char)('0' + fraction % 10);
    len += (size_t)digits;
    out[len] = '\0';
    return len;
}

/* `out` holds at least 32 bytes. */
static size_t format_real(char *out, double x)
{
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    unsigned biased = (unsigned)(bits >> 52 & 0x7ff);
    uint64_t mantissa = bits & ((1ull << 52) - 1);
    size_t len = 0;
    if (biased == 0x7ff)
        return put_text_at(out, mantissa ? "nan" : bits >> 63 ? "-inf" : "inf");
    if (bits >> 63)
        out[len++] = '-';
    /* |x| = mantissa * 2^exponent exactly. */
    int exponent = biased == 0 ? -1074 : (int)biased - 1075;
    if (biased != 0)
        mantissa |= 1ull << 52;
    if (x >= 1e15 || x <= -1e15) {
        big whole;
        big_set(&whole, mantissa);
        if (exponent >= 0)
            big_shift_left(&whole, (unsigned)exponent);
        else
            big_shift_right(&whole, (unsigned)-exponent);
        return len + format_scientific(out + len, &whole);
    }
    if (exponent >= 0) /* below 10^15: a whole number that fits */
        return len + format_fixed(out + len, mantissa << exponent, 0);
    return len + format_fixed(out + len, mantissa, (unsigned)-exponent);
}

#endif

static bool is_digit(char c)
{
    return c >= '0' && c <= '9';
}

#ifndef SEMO_NO_REALS
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
#endif

/* ------------------------------------------------------------------ values */

/* "[+-]digits" within int64. */
static bool parse_int(const char *s, int64_t *out)
{
    bool negative = *s == '-';
    if (*s == '-' || *s == '+')
        s++;
    if (!is_digit(*s))
        return false;
    uint64_t magnitude = 0, limit = negative ? (uint64_t)INT64_MAX + 1 : (uint64_t)INT64_MAX;
    for (; is_digit(*s); s++) {
        uint64_t digit = (uint64_t)(*s - '0');
        if (magnitude > (limit - digit) / 10)
            return false;
        magnitude = magnitude * 10 + digit;
    }
    if (*s != '\0')
        return false;
    *out = negative ? (int64_t)(0 - magnitude) : (int64_t)magnitude;
    return true;
}

/* The index of `word` in the program's word table, or -1. */
static int word_index(const char *word)
{
    const semo_program_desc *p = semo_program();
    for (size_t i = 0; p && i < p->word_count; i++)
        if (strcmp(p->words[i], word) == 0)
            return (int)i;
    return -1;
}

void semo_value_set(semo_value *v, const char *text)
{
    if (!text)
        text = "";
    size_t n = strlen(text);
    if (n >= SEMO_TEXT_MAX) {
        n = SEMO_TEXT_MAX - 1;
        /* Never cut a UTF-8 character in half. */
        while (n > 0 && ((unsigned char)text[n] & 0xC0) == 0x80)
            n--;
    }
    memmove(v->text, text, n);
    v->text[n] = '\0';
    v->type = SEMO_TEXT;
}

void semo_value_set_int(semo_value *v, int64_t n)
{
    v->type = SEMO_INT;
    v->i = n;
}

void semo_value_set_real(semo_value *v, double x)
{
    v->type = SEMO_REAL;
    v->r = x;
}
#ifdef SEMO_NO_REALS
/* A program without reals (the static targets' Makefile says so with
 * -DSEMO_NO_REALS) links no floating point: no soft float on a Cortex-M3. */
#define REALS 0
#else
#define REALS 1
#endif

void semo_value_set_bool(semo_value *v, bool b)
{
    v->type = SEMO_BOOL;
    v->b = b;
}

bool semo_value_set_word(semo_value *v, const char *word)
{
    int index = word ? word_index(word) : -1;
    if (index < 0)
        return false;
    v->type = SEMO_WORD;
    v->word = (unsigned short)index;
    return true;
}

bool semo_value_parse(semo_value *v, semo_type type, const char *text)
{
    if (!text)
        return false;
    switch (type) {
    case SEMO_INT: {
        int64_t n;
        if (!parse_int(text, &n))
            return false;
        semo_value_set_int(v, n);
        return true;
    }
    case SEMO_REAL: {
#if REALS
        double x;
        if (!parse_number(text, &x))
            return false;
        semo_value_set_real(v, x);
        return true;
#else
        return false;
#endif
    }
    case SEMO_BOOL:
        if (strcmp(text, "true") != 0 && strcmp(text, "false") != 0)
            return false;
        semo_value_set_bool(v, text[0] == 't');
        return true;
    case SEMO_WORD:
        return semo_value_set_word(v, text);
    case SEMO_TEXT:
    case SEMO_NONE:
        semo_value_set(v, text);
        return true;
    }
    return false;
}

const char *semo_value_word_text(const semo_value *v)
{
    if (v->type == SEMO_TEXT)
        return v->text;
    const semo_program_desc *p = semo_program();
    if (v->type == SEMO_WORD && p && v->word < p->word_count)
        return p->words[v->word];
    return NULL;
}

bool semo_value_coerce(semo_value *v, semo_type type)
{
    if (type == SEMO_NONE || v->type == type)
        return true;
    if (REALS && type == SEMO_REAL && v->type == SEMO_INT) {
        semo_value_set_real(v, (double)v->i);
        return true;
    }
    if (type == SEMO_TEXT && v->type == SEMO_WORD) {
        const char *word = semo_value_word_text(v);
        if (!word)
            return false;
        semo_value_set(v, word);
        return true;
    }
    if (v->type == SEMO_TEXT) {
        char text[SEMO_TEXT_MAX];
        memcpy(text, v->text, sizeof text);
        return semo_value_parse(v, type, text);
    }
    return false;
}

bool semo_value_in(const semo_value *v, const unsigned short *domain, size_t n)
{
    if (!domain || v->type != SEMO_WORD)
        return true;
    for (size_t k = 0; k < n; k++)
        if (domain[k] == v->word)
            return true;
    return false;
}

#if REALS
static bool as_number(const semo_value *v, double *out)
{
    if (v->type == SEMO_INT)
        *out = (double)v->i;
    else if (v->type == SEMO_REAL)
        *out = v->r;
    else
        return false;
    return true;
}
#endif

static bool ordered(int order, semo_cmp op)
{
    switch (op) {
    case SEMO_EQ: return order == 0;
    case SEMO_NE: return order != 0;
    case SEMO_LT: return order < 0;
    case SEMO_LE: return order <= 0;
    case SEMO_GT: return order > 0;
    case SEMO_GE: return order >= 0;
    }
    return false;
}

bool semo_value_numbers(const semo_value *a, semo_cmp op, const semo_value *b)
{
    if (a->type == SEMO_INT && b->type == SEMO_INT)
        return ordered((a->i > b->i) - (a->i < b->i), op);
#if REALS
    double x, y;
    if (!as_number(a, &x) || !as_number(b, &y) || x != x || y != y)
        return false;
    return ordered((x > y) - (x < y), op);
#else
    return false;
#endif
}

/* Whether two values are the same (see semo_value_words). */
static bool same_value(const semo_value *a, const semo_value *b)
{
    if (a->type == SEMO_NONE || b->type == SEMO_NONE)
        return a->type == b->type;
    if (a->type == SEMO_INT && b->type == SEMO_INT)
        return a->i == b->i;
    if (a->type == SEMO_BOOL && b->type == SEMO_BOOL)
        return a->b == b->b;
    if (a->type == SEMO_WORD && b->type == SEMO_WORD)
        return a->word == b->word; /* identity: one table per program */
#if REALS
    double x, y;
    if (as_number(a, &x) && as_number(b, &y))
        return x == y;
#endif
    const char *s = semo_value_word_text(a), *t = semo_value_word_text(b);
    return s && t && strcmp(s, t) == 0;
}

bool semo_value_words(const semo_value *a, semo_cmp op, const semo_value *b)
{
    if (op != SEMO_EQ && op != SEMO_NE)
        return false;
    return same_value(a, b) == (op == SEMO_EQ);
}

bool semo_value_truthy(const semo_value *v)
{
    switch (v->type) {
    case SEMO_BOOL: return v->b;
    case SEMO_INT: return v->i != 0;
#if REALS
    case SEMO_REAL: return v->r != 0;
#endif
    default: return false;
    }
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

/* A JSON string's characters, without its quotes: control characters
 * escaped, invalid UTF-8 as U+FFFD so that every line parses. */
void semo__json_chars(const semo__sink *sink, const char *text)
{
    static const char hex[] = "0123456789abcdef";
    const unsigned char *s = (const unsigned char *)(text ? text : "");
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
}

static void put_json_string(const semo__sink *sink, const char *text)
{
    put_text(sink, "\"");
    semo__json_chars(sink, text);
    put_text(sink, "\"");
}

/* A value's JSON (semo_value_json) straight to the sink. */
static void put_json_value(const semo__sink *sink, const semo_value *v)
{
    char number[40];
    switch (v ? v->type : SEMO_NONE) {
    case SEMO_INT:
        sink->put(sink->ctx, number, semo__format_i64(number, v->i));
        return;
#if REALS
    case SEMO_REAL:
        if (v->r - v->r != 0) /* inf or nan: JSON has no such number */
            break;
        sink->put(sink->ctx, number, format_real(number, v->r));
        return;
#endif
    case SEMO_BOOL:
        put_text(sink, v->b ? "true" : "false");
        return;
    case SEMO_WORD:
    case SEMO_TEXT: {
        const char *text = semo_value_word_text(v);
        if (!text)
            break;
        put_json_string(sink, text);
        return;
    }
    default:
        break;
    }
    put_text(sink, "null");
}

/* A sink that fills a buffer (semo_value_json). */
typedef struct {
    char *out;
    size_t cap, len;
} buffer_sink;

static void buffer_put(void *ctx, const char *bytes, size_t n)
{
    buffer_sink *b = ctx;
    size_t room = b->cap - 1 - b->len;
    if (n > room)
        n = room;
    memcpy(b->out + b->len, bytes, n);
    b->len += n;
    b->out[b->len] = '\0';
}

size_t semo_value_json(const semo_value *v, char *out, size_t cap)
{
    if (!out || cap == 0)
        return 0;
    buffer_sink b = {out, cap, 0};
    const semo__sink sink = {buffer_put, &b};
    out[0] = '\0';
    put_json_value(&sink, v);
    return b.len;
}

void semo__trace_line(const semo__sink *sink, int64_t t, const char *robot, const char *event, va_list args,
                      const char *value_key, const semo_value *value)
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
    if (value_key) {
        put_text(sink, ",");
        put_json_string(sink, value_key);
        put_text(sink, ":");
        put_json_value(sink, value);
    }
    put_text(sink, "}\n");
}

const char *semo__trace_pair(va_list args, const char *key)
{
    va_list scan;
    va_copy(scan, args);
    const char *found = NULL;
    for (const char *k = va_arg(scan, const char *); k && !found; k = va_arg(scan, const char *)) {
        const char *v = va_arg(scan, const char *);
        if (!v)
            break;
        if (strcmp(k, key) == 0)
            found = v;
    }
    va_end(scan);
    return found;
}

void semo_trace(const char *event, ...)
{
    va_list args;
    va_start(args, event);
    semo__trace_emit(event, NULL, NULL, args);
    va_end(args);
}

void semo_trace_value(const char *event, const char *value_key, const semo_value *value, ...)
{
    va_list args;
    va_start(args, value);
    semo__trace_emit(event, value_key, value, args);
    va_end(args);
}

/* ---------------------------------------------------------- group services */

/* Written by the control task, read by any task: atomics, no lock (the
 * static schedule has no threads; on POSIX a task reads the latest pair the
 * control task set, each half atomically). */
static atomic_int g_group_rank = -1;
static atomic_int g_group_size = 0;

int semo_group_rank(void)
{
    return atomic_load(&g_group_rank);
}

int semo_group_size(void)
{
    return atomic_load(&g_group_size);
}

void semo_group_set(int rank, int size)
{
    if (atomic_load(&g_group_rank) == rank && atomic_load(&g_group_size) == size)
        return;
    atomic_store(&g_group_rank, rank);
    atomic_store(&g_group_size, size);
    char rank_text[24], size_text[24];
    semo__format_i64(rank_text, rank);
    semo__format_i64(size_text, size);
    semo_trace("group", "rank", rank_text, "size", size_text, NULL);
}

/* ---------------------------------------------------------------- battery */

/* The robot's battery level as its control task last read its `BATTERY`
 * sensor value (semo_battery_report), for the status operators see. A
 * `long`: lock-free on cortex-m too, where 64-bit atomics need libatomic. */
static atomic_long g_battery_level;
static atomic_bool g_battery_known;

void semo_battery_report(const semo_value *level)
{
    long rounded;
    if (level->type == SEMO_INT) {
        if (level->i > 1000000000 || level->i < -1000000000)
            return;
        rounded = (long)level->i;
    }
#if REALS /* a program without reals has no real level to read */
    else if (level->type == SEMO_REAL) {
        double x = level->r;
        if (x != x || x > 1e9 || x < -1e9)
            return;
        rounded = (long)(x < 0 ? x - 0.5 : x + 0.5);
    }
#endif
    else {
        return;
    }
    atomic_store(&g_battery_level, rounded);
    atomic_store(&g_battery_known, true);
}

bool semo__battery(long long *level)
{
    if (!atomic_load(&g_battery_known))
        return false;
    *level = atomic_load(&g_battery_level);
    return true;
}

/* ------------------------------------------------- channels and the inbox */

/* The rings are the same on every platform; the platform gives their
 * storage and the hooks around them (semo_internal.h): a lock (none on the
 * static schedule), a wait for the next write (none there: nothing else
 * runs meanwhile), and the wake-up of who waits after a write. */

static bool ring_take(const semo__ring *r, void *out)
{
    if (r->state->count == 0)
        return false;
    memcpy(out, r->storage + r->state->head * r->sample_size, r->sample_size);
    r->state->head = (r->state->head + 1) % r->capacity;
    r->state->count--;
    r->state->stalled = false; /* its reader takes again */
    return true;
}

/* A full ring drops the sample and counts it. */
static bool ring_put(const semo__ring *r, const void *sample)
{
    if (r->state->count == r->capacity) {
        r->state->dropped++;
        return false;
    }
    size_t tail = (r->state->head + r->state->count) % r->capacity;
    memcpy(r->storage + tail * r->sample_size, sample, r->sample_size);
    r->state->count++;
    return true;
}

int UFPort_Initialize(const char *task, const char *port)
{
    const semo_program_desc *p = semo_program();
    if (!p || !task || !port)
        return -1;
    for (size_t i = 0; i < p->channel_count; i++) {
        const semo_channel_desc *c = &p->channels[i];
        bool input = strcmp(c->dst_task, task) == 0 && strcmp(c->dst_port, port) == 0;
        bool output = strcmp(c->src_task, task) == 0 && strcmp(c->src_port, port) == 0;
        if (input || output)
            return (int)i;
    }
    return -1;
}

int UFPort_ReadFromQueue(int port, void *buf, size_t size)
{
    semo__ring r;
    if (!semo__channel_ring(port, &r) || !buf || size != r.sample_size)
        return 0;
    semo__queue_lock(port);
    while (r.state->count == 0 && semo_running() && semo__queue_wait(port, -1))
        ;
    bool read = ring_take(&r, buf);
    semo__queue_unlock(port);
    if (read)
        semo__queue_taken(port);
    return read ? (int)size : 0;
}

int UFPort_WriteToQueue(int port, const void *buf, size_t size)
{
    semo__ring r;
    if (!semo__channel_ring(port, &r) || !buf || size != r.sample_size)
        return 0;
    semo__queue_lock(port);
    bool written = ring_put(&r, buf);
    semo__queue_unlock(port);
    if (written)
        semo__queue_written(port);
    return written ? (int)size : 0;
}

/* A message channel's write: waits for room as `room` says (semo_runtime.h). */
static int write_waiting(int port, const void *buf, size_t size, bool patient)
{
    semo__ring r;
    if (!semo__channel_ring(port, &r) || !buf || size != r.sample_size)
        return 0;
    semo__room_wait room = {patient, false, 0};
    semo__queue_lock(port);
    bool waits = patient || !r.state->stalled;
    while (r.state->count == r.capacity && semo_running() && waits && semo__queue_wait_room(port, &room))
        ;
    if (r.state->count == r.capacity && !patient && semo_running())
        r.state->stalled = true; /* its reader is not taking: the next ones do not wait */
    bool written = ring_put(&r, buf);
    semo__queue_unlock(port);
    if (written)
        semo__queue_written(port);
    return written ? (int)size : 0;
}

int semo_port_send(int port, const void *buf, size_t size)
{
    return write_waiting(port, buf, size, true);
}

int semo_port_offer(int port, const void *buf, size_t size)
{
    return write_waiting(port, buf, size, false);
}

/* Taken and sent under the channel's lock: two threads forwarding from
 * one channel (CommSend, and the control task running CommSend's body when
 * it finishes) send in the order they took, never the other way round. */
bool semo_port_forward(int port, const char *to_team, semo_msg_kind kind, const char *key)
{
    semo__ring r;
    if (!semo__channel_ring(port, &r) || r.sample_size != sizeof(semo_value))
        return false;
    semo_value v;
    semo__queue_lock(port);
    bool taken = ring_take(&r, &v);
    if (taken)
        semo_comm_send(to_team, kind, key, &v);
    semo__queue_unlock(port);
    if (taken)
        semo__queue_taken(port);
    return taken;
}

int UFPort_GetNumOfAvailableData(int port)
{
    semo__ring r;
    if (!semo__channel_ring(port, &r))
        return -1;
    semo__queue_lock(port);
    int n = (int)r.state->count;
    semo__queue_unlock(port);
    return n;
}

void semo__trace_dropped_samples(void)
{
    const semo_program_desc *p = semo_program();
    for (size_t i = 0; p && i < p->channel_count; i++) {
        semo__ring r;
        if (!semo__channel_ring((int)i, &r))
            continue;
        semo__queue_lock((int)i);
        unsigned long dropped = r.state->dropped;
        semo__queue_unlock((int)i);
        if (dropped == 0)
            continue;
        const semo_channel_desc *d = &p->channels[i];
        char count[21], name[256];
        semo__format_i64(count, (int64_t)dropped);
        /* "Src.port->Dst.port", cut to fit. */
        size_t len = 0;
        const char *parts[] = {d->src_task, ".", d->src_port, "->", d->dst_task, ".", d->dst_port};
        for (size_t k = 0; k < sizeof parts / sizeof parts[0]; k++)
            for (const char *c = parts[k]; *c && len + 1 < sizeof name; c++)
                name[len++] = *c;
        name[len] = '\0';
        semo_trace("dropped", "channel", name, "count", count, NULL);
    }
}

/* Messages received and not yet taken. */
static semo_message g_inbox[SEMO_INBOX];
static semo_channel_state g_inbox_state;
static const semo__ring g_inbox_ring = {(unsigned char *)g_inbox, &g_inbox_state, SEMO_INBOX, sizeof(semo_message)};

static bool g_inbox_polled; /* some task called semo_comm_poll */

void semo__inbox_reset(void)
{
    g_inbox_state = (semo_channel_state){0};
    g_inbox_polled = false;
}

bool semo__inbox_waiting(void)
{
    semo__queue_lock(SEMO__INBOX);
    bool waiting = g_inbox_polled && g_inbox_state.count > 0;
    semo__queue_unlock(SEMO__INBOX);
    return waiting;
}

bool semo__inbox_unpolled_full(void)
{
    semo__queue_lock(SEMO__INBOX);
    bool full = !g_inbox_polled && g_inbox_state.count == g_inbox_ring.capacity;
    semo__queue_unlock(SEMO__INBOX);
    return full;
}

bool semo__inbox_holds_back(void)
{
    semo__queue_lock(SEMO__INBOX);
    bool full = g_inbox_polled && g_inbox_state.count == g_inbox_ring.capacity;
    semo__queue_unlock(SEMO__INBOX);
    return full;
}


/* ---------------------------------------------------------- task control */

typedef enum { CONTROL_RUN, CONTROL_CALL, CONTROL_STOP, CONTROL_SUSPEND, CONTROL_RESUME } control_op;

/* The one switch of task control, over the platform's record of the task. */
static int control(const char *name, control_op op)
{
    semo__task_control *c = semo__control_begin(name);
    if (!c)
        return -1;
    switch (op) {
    case CONTROL_RUN:
        c->repeat = true;
        c->stop_requested = false;
        if (c->state == SEMO_TASK_IDLE)
            c->state = SEMO_TASK_RUNNING;
        break;
    case CONTROL_CALL:
        if (c->state == SEMO_TASK_IDLE || !c->repeat) {
            c->repeat = false;
            c->calls++;
            c->stop_requested = false;
            if (c->state == SEMO_TASK_IDLE)
                c->state = SEMO_TASK_RUNNING;
        }
        break;
    case CONTROL_STOP:
        if (c->state != SEMO_TASK_IDLE)
            c->stop_requested = true;
        break;
    case CONTROL_SUSPEND:
        if (c->state == SEMO_TASK_RUNNING)
            c->state = SEMO_TASK_SUSPENDED;
        break;
    case CONTROL_RESUME:
        if (c->state == SEMO_TASK_SUSPENDED)
            c->state = SEMO_TASK_RUNNING;
        break;
    }
    semo__control_end(c);
    return 0;
}

int UFControl_RunTask(const char *task) { return control(task, CONTROL_RUN); }
int UFControl_CallTask(const char *task) { return control(task, CONTROL_CALL); }
int UFControl_StopTask(const char *task) { return control(task, CONTROL_STOP); }
int UFControl_SuspendTask(const char *task) { return control(task, CONTROL_SUSPEND); }
int UFControl_ResumeTask(const char *task) { return control(task, CONTROL_RESUME); }

/* -------------------------------------------------------------- messages */

void semo__deliver(const semo_message *msg)
{
    /* A robot whose mission has finished (or that is stopping) takes no
     * more messages, as the simulator's stopped robot hears none: what
     * arrives after the control task's `finish` is not queued. */
    const semo_program_desc *program = semo_program();
    if (!semo_running() || (program && !program->receives))
        return;
    semo__queue_lock(SEMO__INBOX);
    /* A full inbox holds back the deliverer, and through it the transport
     * (MQTT: the broker keeps the rest of a burst, such as what it queued
     * for a robot that reconnects), rather than losing a message; where the
     * platform cannot wait (the static schedule) the message is dropped. */
    int64_t deadline = semo_now_ms() + SEMO__INBOX_UNPOLLED_WAIT_MS;
    while (g_inbox_state.count == g_inbox_ring.capacity && semo_running() &&
           (g_inbox_polled || semo_now_ms() < deadline) &&
           semo__queue_wait(SEMO__INBOX, g_inbox_polled ? -1 : deadline))
        ;
    bool queued = ring_put(&g_inbox_ring, msg);
    semo__queue_unlock(SEMO__INBOX);
    if (queued)
        semo__queue_written(SEMO__INBOX);
    else
        semo_trace("drop", "from", msg->from_team, "key", msg->key, "reason",
                   semo_running() ? "inbox full" : "stopping", NULL);
}

int semo_comm_poll(semo_message *out, int64_t timeout_ms)
{
    if (!out)
        return 0;
    int64_t deadline = timeout_ms < 0 ? -1 : semo_now_ms() + timeout_ms;
    semo__queue_lock(SEMO__INBOX);
    g_inbox_polled = true;
    semo__inbox_polled();
    while (g_inbox_state.count == 0 && semo_running() && (deadline < 0 || semo_now_ms() < deadline) &&
           semo__queue_wait(SEMO__INBOX, deadline))
        ;
    /* Once finished, what is still queued is not taken either. */
    bool got = semo_running() && ring_take(&g_inbox_ring, out);
    semo__queue_unlock(SEMO__INBOX);
    if (got)
        semo__queue_written(SEMO__INBOX); /* room for a held-back delivery */
    if (got)
        semo_trace_value("receive", "value", &out->value, "from", out->from_team, "from_robot", out->from_robot,
                         "key", out->key, NULL);
    return got;
}

int semo__comm_send_local(const char *to_team, semo_msg_kind kind, const char *key, const semo_value *value)
{
    if (!semo_program() || !to_team || !key || !value || strlen(key) >= sizeof ((semo_message *)0)->key ||
        (kind != SEMO_MSG_SEND && kind != SEMO_MSG_PUBLISH))
        return -1;
    semo_trace_value("send", "value", value, "to", to_team, "key", key, NULL);
    /* The operator console: the trace is its record. */
    return strcmp(to_team, "USER") == 0 ? 1 : 0;
}

/* ------------------------------------------------------------ the wire */

static size_t put_field(unsigned char *out, const char *text)
{
    size_t n = strlen(text);
    if (n > 255)
        n = 255;
    out[0] = (unsigned char)n;
    memcpy(out + 1, text, n);
    return n + 1;
}

static size_t field_size(const char *text)
{
    size_t n = strlen(text);
    return 1 + (n > 255 ? 255 : n);
}

size_t semo__encoded_size(const semo_message *m)
{
    size_t n = 6 + field_size(m->from_team) + field_size(m->from_robot) + field_size(m->key) + 1;
    const semo_value *v = &m->value;
    if (v->type == SEMO_INT || v->type == SEMO_REAL) {
        n += 8;
    } else if (v->type == SEMO_BOOL) {
        n += 1;
    } else if (v->type == SEMO_WORD || v->type == SEMO_TEXT) {
        const char *text = semo_value_word_text(v);
        n += field_size(text ? text : "");
    }
    return n;
}

size_t semo__encode_message(const semo_message *m, unsigned char *out)
{
    size_t n = 5;
    memcpy(out, SEMO__DATAGRAM_MAGIC, 5);
    out[n++] = (unsigned char)m->kind;
    n += put_field(out + n, m->from_team);
    n += put_field(out + n, m->from_robot);
    n += put_field(out + n, m->key);
    const semo_value *v = &m->value;
    uint64_t bits = 0;
    switch (v->type) {
    case SEMO_INT:
    case SEMO_REAL:
        if (v->type == SEMO_INT)
            bits = (uint64_t)v->i;
        else
            memcpy(&bits, &v->r, sizeof bits);
        out[n++] = v->type;
        for (int shift = 56; shift >= 0; shift -= 8)
            out[n++] = (unsigned char)(bits >> shift);
        break;
    case SEMO_BOOL:
        out[n++] = SEMO_BOOL;
        out[n++] = v->b ? 1 : 0;
        break;
    case SEMO_WORD:
    case SEMO_TEXT: {
        /* Words go as their text: word tables are per program. */
        const char *text = semo_value_word_text(v);
        out[n++] = v->type;
        n += put_field(out + n, text ? text : "");
        break;
    }
    default:
        out[n++] = SEMO_NONE;
        break;
    }
    return n;
}

static bool take_field(const unsigned char *in, size_t len, size_t *at, char *out, size_t cap)
{
    if (*at >= len)
        return false;
    size_t n = in[(*at)++];
    if (n >= cap || n > len - *at || memchr(in + *at, '\0', n))
        return false;
    memcpy(out, in + *at, n);
    out[n] = '\0';
    *at += n;
    return true;
}

static bool take_value(const unsigned char *in, size_t len, size_t *at, semo_value *v)
{
    if (*at >= len)
        return false;
    unsigned char type = in[(*at)++];
    switch (type) {
    case SEMO_NONE:
        *v = (semo_value){.type = SEMO_NONE};
        return true;
    case SEMO_INT:
    case SEMO_REAL: {
        if (len - *at < 8)
            return false;
        uint64_t bits = 0;
        for (int i = 0; i < 8; i++)
            bits = bits << 8 | in[(*at)++];
        if (type == SEMO_INT) {
            semo_value_set_int(v, (int64_t)bits);
        } else {
            double x;
            memcpy(&x, &bits, sizeof x);
            semo_value_set_real(v, x);
        }
        return true;
    }
    case SEMO_BOOL:
        if (*at >= len || in[*at] > 1)
            return false;
        semo_value_set_bool(v, in[(*at)++] == 1);
        return true;
    case SEMO_WORD:
    case SEMO_TEXT: {
        char text[256];
        if (!take_field(in, len, at, text, sizeof text) || strlen(text) >= SEMO_TEXT_MAX)
            return false;
        /* A word this program does not know stays its text: it equals
         * only the same text, as it would as a word. */
        if (type == SEMO_TEXT || !semo_value_set_word(v, text))
            semo_value_set(v, text);
        return true;
    }
    default:
        return false;
    }
}

bool semo__decode_message(const unsigned char *in, size_t len, semo_message *m)
{
    size_t at = 6;
    if (len < at || memcmp(in, SEMO__DATAGRAM_MAGIC, 5) != 0)
        return false;
    m->kind = (char)in[5];
    if (m->kind != SEMO_MSG_SEND && m->kind != SEMO_MSG_PUBLISH)
        return false;
    return take_field(in, len, &at, m->from_team, sizeof m->from_team) &&
           take_field(in, len, &at, m->from_robot, sizeof m->from_robot) &&
           take_field(in, len, &at, m->key, sizeof m->key) && take_value(in, len, &at, &m->value) && at == len;
}

#ifdef SEMO_SIM
/* ------------------------------------------------------------ simulation */

/* The battery level at `t`: linear between the scenario's points, the first
 * before them and the last after them (the simulator's battery_level, the
 * same operations in the same order). */
static double battery_level(int64_t t)
{
    const semo__sim_battery_entry *b = semo__scenario.battery;
    size_t count = semo__scenario.battery_count;
    if (t <= b[0].at)
        return b[0].level;
    for (size_t i = 1; i < count; i++)
        if (t <= b[i].at)
            return b[i - 1].level + (b[i].level - b[i - 1].level) * (double)(t - b[i - 1].at) / (double)(b[i].at - b[i - 1].at);
    return b[count - 1].level;
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

double semo__sim_battery_at(int64_t t)
{
    return round_half_away(battery_level(t));
}

/* Both simulation platforms' (semo_sim.c, semo_static.c): the scenario's
 * battery level now, rounded. */
bool semo_sim_battery(long long *level)
{
    if (semo__scenario.battery_count == 0)
        return false;
    if (level)
        *level = (long long)semo__sim_battery_at(semo_now_ms());
    return true;
}
/* Both simulation platforms': the scenario's latest sample of `value` at
 * this instant; BATTERY without one is the scenario's battery level (the
 * simulator's rule). */
bool semo_sim_sensor(const char *value, semo_type type, semo_value *out)
{
    const semo__sim_sensor_entry *latest = NULL;
    int64_t now = semo_now_ms();
    for (size_t i = 0; value && i < semo__scenario.sensor_count; i++) {
        const semo__sim_sensor_entry *e = &semo__scenario.sensors[i];
        if (e->at <= now && strcmp(e->value, value) == 0 && (!latest || e->at >= latest->at))
            latest = e;
    }
    semo_value read;
    if (latest)
        return semo_value_parse(out ? out : &read, type, latest->is);
    if (value && strcmp(value, "BATTERY") == 0 && semo__scenario.battery_count > 0) {
        /* A whole number (semo__sim_battery_at rounds), of a scenario's level. */
        char text[21];
        semo__format_i64(text, (int64_t)semo__sim_battery_at(now));
        return semo_value_parse(out ? out : &read, type, text);
    }
    return false;
}
#endif

int64_t semo__on_grid(int64_t at, int64_t first, int64_t period_ms)
{
    if (at == INT64_MAX || first < 0 || at <= first || period_ms <= 0)
        return at;
    int64_t periods = (at - first) / period_ms + ((at - first) % period_ms != 0);
    if (periods > (INT64_MAX - first) / period_ms)
        return INT64_MAX;
    return first + periods * period_ms;
}
