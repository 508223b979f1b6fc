/* Reading a monitor plugin's settings JSON in C (ABI minor 1, beside monitor_plugin.h; header
 * only: include it in the one file that reads the settings, nothing to link).
 *
 * armfault passes a plugin's "settings" object to create as JSON text (settings_json). These
 * functions read its top-level keys by name, so a plugin need not scan JSON by hand:
 *
 *     double window_s = 2.0;                      (the default, kept when the key is absent)
 *     int latch = 0;
 *     char mode[32] = "watch";
 *     if (armfault_setting_check_keys(json, known, 3, error, error_size) < 0 ||
 *         armfault_setting_number(json, "window_s", &window_s, error, error_size) < 0 ||
 *         armfault_setting_bool(json, "latch", &latch, error, error_size) < 0 ||
 *         armfault_setting_string(json, "mode", mode, sizeof mode, error, error_size) < 0)
 *       return NULL;                                (error holds the message)
 *
 * Each returns ARMFAULT_SETTING_FOUND (1) and stores the value; ARMFAULT_SETTING_MISSING (0)
 * when the object has no such key, leaving the value as it was; ARMFAULT_SETTING_ERROR (-1) with
 * a NUL-terminated message in `error` (at most error_size bytes) naming the key and what is
 * wrong: the text is not one JSON object, the key appears twice, or its value has another type
 * (a number asked, a string given; `null` is not a number). The whole text is checked on every
 * call, so a malformed settings text is an error whatever key is asked.
 *
 * What it reads: the keys of the top-level object (compared byte for byte after the JSON
 * escapes are decoded; keys of more than 255 bytes are never equal to one asked for); numbers
 * as doubles (JSON's grammar, converted independently of the C locale; beyond a double is an
 * error); `true`/`false` as 1/0; strings decoded to UTF-8 (\uXXXX escapes and surrogate pairs
 * included; a string that does not fit `value_size` with its NUL is an error, and one holding
 * \u0000 is refused). Nested objects and arrays are checked and skipped, not read: keep a
 * plugin's settings flat. Nesting deeper than 64 is an error.
 *
 * Thread safety: the functions keep no state and only read `json`; any thread may call them.
 * They never read past the terminating NUL of `json`. Written in the common subset of C99 and
 * C++, so a C++ plugin may include it too. Tests: tests/core/monitors/settings_helper_test.c.
 */
#ifndef ARMFAULT_MONITOR_SETTINGS_H_
#define ARMFAULT_MONITOR_SETTINGS_H_

#include <locale.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ARMFAULT_SETTING_FOUND 1
#define ARMFAULT_SETTING_MISSING 0
#define ARMFAULT_SETTING_ERROR (-1)

/* ------------------------------------------------------------------ internals (armfault_s_*) */

static inline const char* armfault_s_space(const char* p) {
  while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r') p++;
  return p;
}

/* Appends byte `b` to out[*n] when it fits with a NUL after it; counts it either way. */
static inline void armfault_s_put(char* out, size_t out_size, size_t* n, unsigned b) {
  if (out && *n + 1 < out_size) out[*n] = (char)b;
  (*n)++;
}

static inline int armfault_s_hex4(const char* p, unsigned* value) {
  int k;
  *value = 0;
  for (k = 0; k < 4; k++) {
    const char c = p[k];
    unsigned d;
    if (c >= '0' && c <= '9') d = (unsigned)(c - '0');
    else if (c >= 'a' && c <= 'f') d = (unsigned)(c - 'a' + 10);
    else if (c >= 'A' && c <= 'F') d = (unsigned)(c - 'A' + 10);
    else return 0;
    *value = *value * 16 + d;
  }
  return 1;
}

/* The JSON string at p (its opening quote), decoded into out (NUL-terminated; NULL: decode
 * nothing). Returns the byte after the closing quote, or NULL when malformed. *length: the
 * decoded length in bytes (it did not fit when *length >= out_size); *has_nul: it holds \u0000. */
static inline const char* armfault_s_string(const char* p, char* out, size_t out_size, size_t* length, int* has_nul) {
  size_t n = 0;
  *has_nul = 0;
  if (*p++ != '"') return NULL;
  for (;;) {
    const unsigned char c = (unsigned char)*p++;
    if (c == '"') break;
    if (c < 0x20) return NULL; /* a control character, or the end of the text */
    if (c != '\\') {
      armfault_s_put(out, out_size, &n, c);
      continue;
    }
    switch (*p++) {
      case '"': armfault_s_put(out, out_size, &n, '"'); break;
      case '\\': armfault_s_put(out, out_size, &n, '\\'); break;
      case '/': armfault_s_put(out, out_size, &n, '/'); break;
      case 'b': armfault_s_put(out, out_size, &n, '\b'); break;
      case 'f': armfault_s_put(out, out_size, &n, '\f'); break;
      case 'n': armfault_s_put(out, out_size, &n, '\n'); break;
      case 'r': armfault_s_put(out, out_size, &n, '\r'); break;
      case 't': armfault_s_put(out, out_size, &n, '\t'); break;
      case 'u': {
        unsigned u;
        if (!armfault_s_hex4(p, &u)) return NULL;
        p += 4;
        if (u >= 0xD800 && u <= 0xDBFF) { /* a high surrogate: its low half must follow */
          unsigned low;
          if (p[0] != '\\' || p[1] != 'u' || !armfault_s_hex4(p + 2, &low) || low < 0xDC00 || low > 0xDFFF) return NULL;
          p += 6;
          u = 0x10000 + ((u - 0xD800) << 10) + (low - 0xDC00);
        } else if (u >= 0xDC00 && u <= 0xDFFF) {
          return NULL; /* a low surrogate alone */
        }
        if (u == 0) *has_nul = 1;
        if (u < 0x80) {
          armfault_s_put(out, out_size, &n, u);
        } else if (u < 0x800) {
          armfault_s_put(out, out_size, &n, 0xC0 | (u >> 6));
          armfault_s_put(out, out_size, &n, 0x80 | (u & 0x3F));
        } else if (u < 0x10000) {
          armfault_s_put(out, out_size, &n, 0xE0 | (u >> 12));
          armfault_s_put(out, out_size, &n, 0x80 | ((u >> 6) & 0x3F));
          armfault_s_put(out, out_size, &n, 0x80 | (u & 0x3F));
        } else {
          armfault_s_put(out, out_size, &n, 0xF0 | (u >> 18));
          armfault_s_put(out, out_size, &n, 0x80 | ((u >> 12) & 0x3F));
          armfault_s_put(out, out_size, &n, 0x80 | ((u >> 6) & 0x3F));
          armfault_s_put(out, out_size, &n, 0x80 | (u & 0x3F));
        }
        break;
      }
      default: return NULL;
    }
  }
  if (out && out_size > 0) out[n < out_size ? n : out_size - 1] = '\0';
  *length = n;
  return p;
}

/* The end of the JSON number at p, or NULL when p does not start one. */
static inline const char* armfault_s_number_end(const char* p) {
  if (*p == '-') p++;
  if (*p == '0') {
    p++;
  } else if (*p >= '1' && *p <= '9') {
    while (*p >= '0' && *p <= '9') p++;
  } else {
    return NULL;
  }
  if (*p == '.') {
    p++;
    if (!(*p >= '0' && *p <= '9')) return NULL;
    while (*p >= '0' && *p <= '9') p++;
  }
  if (*p == 'e' || *p == 'E') {
    p++;
    if (*p == '+' || *p == '-') p++;
    if (!(*p >= '0' && *p <= '9')) return NULL;
    while (*p >= '0' && *p <= '9') p++;
  }
  return p;
}

/* The end of the JSON value at p (white space before it skipped), or NULL when malformed. */
static inline const char* armfault_s_value_end(const char* p, int depth) {
  size_t length;
  int has_nul;
  p = armfault_s_space(p);
  if (depth > 64) return NULL;
  switch (*p) {
    case '"': return armfault_s_string(p, NULL, 0, &length, &has_nul);
    case 't': return strncmp(p, "true", 4) == 0 ? p + 4 : NULL;
    case 'f': return strncmp(p, "false", 5) == 0 ? p + 5 : NULL;
    case 'n': return strncmp(p, "null", 4) == 0 ? p + 4 : NULL;
    case '{':
    case '[': {
      const char close = *p == '{' ? '}' : ']';
      const int object = *p == '{';
      p = armfault_s_space(p + 1);
      if (*p == close) return p + 1;
      for (;;) {
        if (object) {
          p = armfault_s_string(p, NULL, 0, &length, &has_nul);
          if (!p) return NULL;
          p = armfault_s_space(p);
          if (*p++ != ':') return NULL;
        }
        p = armfault_s_value_end(p, depth + 1);
        if (!p) return NULL;
        p = armfault_s_space(p);
        if (*p == close) return p + 1;
        if (*p++ != ',') return NULL;
        p = armfault_s_space(p);
      }
    }
    default: return armfault_s_number_end(p);
  }
}

/* What a value is, for messages. */
static inline const char* armfault_s_kind(const char* v) {
  switch (*v) {
    case '"': return "a string";
    case 't': return "true";
    case 'f': return "false";
    case 'n': return "null";
    case '{': return "an object";
    case '[': return "an array";
    default: return "a number";
  }
}

/* Checks that `json` is one JSON object and finds its key `key` (NULL: none): *value_at is set
 * to the value's first byte when found. With `known` (known_count names), every key must be
 * one of them. Returns FOUND, MISSING or ERROR (with the message). */
static inline int armfault_s_scan(const char* json, const char* key, const char** value_at, const char* const* known,
                                  int known_count, char* error, size_t error_size) {
  const char* p;
  const char* found = NULL;
  char name[256];
  if (!json) {
    snprintf(error, error_size, "settings: no text (NULL)");
    return ARMFAULT_SETTING_ERROR;
  }
  p = armfault_s_space(json);
  if (*p != '{') goto bad;
  p = armfault_s_space(p + 1);
  if (*p == '}') {
    p++;
  } else {
    for (;;) {
      size_t length;
      int has_nul, fits;
      const char* value;
      const char* next = armfault_s_string(p, name, sizeof name, &length, &has_nul);
      if (!next) goto bad; /* p stays at what is malformed, for the message */
      fits = length < sizeof name && !has_nul;
      p = armfault_s_space(next);
      if (*p != ':') goto bad;
      p = value = armfault_s_space(p + 1);
      next = armfault_s_value_end(value, 1);
      if (!next) goto bad;
      p = next;
      if (known) {
        int k;
        for (k = 0; k < known_count; k++) {
          if (fits && strcmp(name, known[k]) == 0) break;
        }
        if (k == known_count) {
          size_t used;
          snprintf(error, error_size, "unknown setting \"%.60s\" (known:", name);
          for (k = 0; k < known_count; k++) {
            used = strlen(error);
            if (used + 1 < error_size) snprintf(error + used, error_size - used, "%s %s", k ? "," : "", known[k]);
          }
          used = strlen(error);
          if (used + 1 < error_size) snprintf(error + used, error_size - used, ")");
          return ARMFAULT_SETTING_ERROR;
        }
      }
      if (key && fits && strcmp(name, key) == 0) {
        if (found) {
          snprintf(error, error_size, "setting \"%s\" appears twice", key);
          return ARMFAULT_SETTING_ERROR;
        }
        found = value;
      }
      p = armfault_s_space(p);
      if (*p == '}') {
        p++;
        break;
      }
      if (*p != ',') goto bad;
      p = armfault_s_space(p + 1);
    }
  }
  p = armfault_s_space(p);
  if (*p != '\0') goto bad;
  if (!found) return ARMFAULT_SETTING_MISSING;
  *value_at = found;
  return ARMFAULT_SETTING_FOUND;
bad:
  snprintf(error, error_size, "settings: not one JSON object (at byte %ld of %.60s)", (long)(p - json), json);
  return ARMFAULT_SETTING_ERROR;
}

/* ------------------------------------------------------------------ the functions */

/* Fails unless every top-level key of `json` is one of known[0 .. known_count - 1]: the error
 * names the first unknown key and lists the known ones. Returns FOUND (all known) or ERROR. */
static inline int armfault_setting_check_keys(const char* json, const char* const* known, int known_count, char* error,
                                              size_t error_size) {
  const char* unused = NULL;
  const int r = armfault_s_scan(json, NULL, &unused, known, known_count, error, error_size);
  return r == ARMFAULT_SETTING_ERROR ? r : ARMFAULT_SETTING_FOUND;
}

/* The number at `key` into *value. */
static inline int armfault_setting_number(const char* json, const char* key, double* value, char* error,
                                          size_t error_size) {
  const char* v = NULL;
  const char* end;
  char text[128];
  char* parsed_end;
  size_t n, k;
  double x;
  const int r = armfault_s_scan(json, key, &v, NULL, 0, error, error_size);
  if (r != ARMFAULT_SETTING_FOUND) return r;
  end = armfault_s_number_end(v);
  if (!end) {
    snprintf(error, error_size, "setting \"%s\": expected a number, got %s", key, armfault_s_kind(v));
    return ARMFAULT_SETTING_ERROR;
  }
  n = (size_t)(end - v);
  if (n >= sizeof text) {
    snprintf(error, error_size, "setting \"%s\": a number of more than %d characters", key, (int)sizeof text - 1);
    return ARMFAULT_SETTING_ERROR;
  }
  memcpy(text, v, n);
  text[n] = '\0';
  /* strtod reads the C locale's decimal point: JSON's '.' becomes that (a one-byte one). */
  {
    const struct lconv* lc = localeconv();
    if (lc && lc->decimal_point && lc->decimal_point[0] && !lc->decimal_point[1]) {
      for (k = 0; k < n; k++) {
        if (text[k] == '.') text[k] = lc->decimal_point[0];
      }
    }
  }
  x = strtod(text, &parsed_end);
  if (parsed_end != text + n || !isfinite(x)) {
    snprintf(error, error_size, "setting \"%s\": %.40s is beyond a double", key, text);
    return ARMFAULT_SETTING_ERROR;
  }
  *value = x;
  return ARMFAULT_SETTING_FOUND;
}

/* The boolean at `key` into *value (1 for true, 0 for false). */
static inline int armfault_setting_bool(const char* json, const char* key, int* value, char* error, size_t error_size) {
  const char* v = NULL;
  const int r = armfault_s_scan(json, key, &v, NULL, 0, error, error_size);
  if (r != ARMFAULT_SETTING_FOUND) return r;
  if (*v != 't' && *v != 'f') {
    snprintf(error, error_size, "setting \"%s\": expected true or false, got %s", key, armfault_s_kind(v));
    return ARMFAULT_SETTING_ERROR;
  }
  *value = *v == 't';
  return ARMFAULT_SETTING_FOUND;
}

/* The string at `key`, decoded, into value[0 .. value_size - 1] with its NUL. On ERROR and
 * MISSING `value` is unchanged. */
static inline int armfault_setting_string(const char* json, const char* key, char* value, size_t value_size,
                                          char* error, size_t error_size) {
  const char* v = NULL;
  size_t length;
  int has_nul;
  const int r = armfault_s_scan(json, key, &v, NULL, 0, error, error_size);
  if (r != ARMFAULT_SETTING_FOUND) return r;
  if (*v != '"') {
    snprintf(error, error_size, "setting \"%s\": expected a string, got %s", key, armfault_s_kind(v));
    return ARMFAULT_SETTING_ERROR;
  }
  armfault_s_string(v, NULL, 0, &length, &has_nul); /* valid: the scan read it */
  if (has_nul) {
    snprintf(error, error_size, "setting \"%s\": a string holding \\u0000", key);
    return ARMFAULT_SETTING_ERROR;
  }
  if (length >= value_size) {
    snprintf(error, error_size, "setting \"%s\": a string of %lu bytes, at most %lu fit", key, (unsigned long)length,
             (unsigned long)(value_size ? value_size - 1 : 0));
    return ARMFAULT_SETTING_ERROR;
  }
  armfault_s_string(v, value, value_size, &length, &has_nul);
  return ARMFAULT_SETTING_FOUND;
}

#endif /* ARMFAULT_MONITOR_SETTINGS_H_ */
