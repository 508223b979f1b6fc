/* include/armfault/monitor_settings.h, in C99 (built with -Wall -Wextra -Werror -pedantic):
 * numbers, booleans and strings by key; a missing key leaves the value; a wrong type, a key
 * twice, malformed JSON, a string too long and an unknown key are errors naming the key; the
 * number conversion does not follow the C locale's decimal comma. Prints one line per failed
 * check and "N passed, M failed"; exits non-zero on failure. */
#include <locale.h>
#include <stdio.h>
#include <string.h>

#include "armfault/monitor_settings.h"

static int passed = 0, failed = 0;

static void check(int ok, const char* what, const char* detail) {
  if (ok) {
    passed++;
  } else {
    failed++;
    printf("FAIL: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
  }
}

/* The number at key in json must read as `want`. */
static void number_is(const char* json, const char* key, double want) {
  char error[256] = "";
  double x = -12345;
  const int r = armfault_setting_number(json, key, &x, error, sizeof error);
  char what[300];
  snprintf(what, sizeof what, "number %s in %s", key, json);
  check(r == ARMFAULT_SETTING_FOUND && x == want, what, error);
}

/* Reading key as `type` must fail with a message containing `needle`, value unchanged. */
static void error_is(const char* json, const char* key, char type, const char* needle) {
  char error[256] = "";
  char what[400];
  int r;
  double x = 7;
  int b = 7;
  char s[8] = "keep";
  if (type == 'n') r = armfault_setting_number(json, key, &x, error, sizeof error);
  else if (type == 'b') r = armfault_setting_bool(json, key, &b, error, sizeof error);
  else r = armfault_setting_string(json, key, s, sizeof s, error, sizeof error);
  snprintf(what, sizeof what, "%c %s in %s is an error with '%s'", type, key, json, needle);
  check(r == ARMFAULT_SETTING_ERROR && strstr(error, needle) != NULL && x == 7 && b == 7 && strcmp(s, "keep") == 0,
        what, error);
}

int main(void) {
  char error[256];
  char s[32];
  double x;
  int b, r;

  /* Numbers: as armfault passes them (compact), and as a person writes them. */
  number_is("{\"kt_worn\":0.85}", "kt_worn", 0.85);
  number_is("{ \"a\" : 1 , \"b\" : -2.5e-3 }", "b", -2.5e-3);
  number_is("{\"a\":{\"b\":[1,2,{\"c\":3}]},\"b\":1E2}", "b", 100);
  number_is("\n{\"n\":0}\n", "n", 0);
  number_is("{\"big\":1.7976931348623157e308}", "big", 1.7976931348623157e308);

  /* A missing key: MISSING, the default kept. */
  x = 2.0;
  r = armfault_setting_number("{\"other\":1}", "window_s", &x, error, sizeof error);
  check(r == ARMFAULT_SETTING_MISSING && x == 2.0, "a missing key keeps the default", NULL);
  r = armfault_setting_number("{}", "window_s", &x, error, sizeof error);
  check(r == ARMFAULT_SETTING_MISSING && x == 2.0, "an empty object", NULL);
  /* Only top-level keys: one inside a nested object is not read. */
  r = armfault_setting_number("{\"limits\":{\"kt\":0.5}}", "kt", &x, error, sizeof error);
  check(r == ARMFAULT_SETTING_MISSING && x == 2.0, "a nested key is not a top-level one", NULL);

  /* Booleans and strings. */
  b = 5;
  r = armfault_setting_bool("{\"latch\":true}", "latch", &b, error, sizeof error);
  check(r == ARMFAULT_SETTING_FOUND && b == 1, "true", error);
  r = armfault_setting_bool("{\"latch\":false}", "latch", &b, error, sizeof error);
  check(r == ARMFAULT_SETTING_FOUND && b == 0, "false", error);
  r = armfault_setting_string("{\"mode\":\"watch\"}", "mode", s, sizeof s, error, sizeof error);
  check(r == ARMFAULT_SETTING_FOUND && strcmp(s, "watch") == 0, "a string", error);
  r = armfault_setting_string("{\"m\":\"a\\\"b\\\\c\\n\\u00e9\\ud83d\\ude00\"}", "m", s, sizeof s, error, sizeof error);
  check(r == ARMFAULT_SETTING_FOUND && strcmp(s, "a\"b\\c\n\xc3\xa9\xf0\x9f\x98\x80") == 0, "escapes decoded to UTF-8", error);
  r = armfault_setting_number("{\"k\\u0074_worn\":0.7}", "kt_worn", &x, error, sizeof error);
  check(r == ARMFAULT_SETTING_FOUND && x == 0.7, "an escaped key matches its decoded name", error);
  r = armfault_setting_string("{\"m\":\"1234567\"}", "m", s, 8, error, sizeof error);
  check(r == ARMFAULT_SETTING_FOUND && strcmp(s, "1234567") == 0, "a string that just fits", error);

  /* Wrong types: an error naming the key and what it got; the value unchanged. */
  error_is("{\"kt_worn\":\"0.85\"}", "kt_worn", 'n', "setting \"kt_worn\": expected a number, got a string");
  error_is("{\"kt_worn\":null}", "kt_worn", 'n', "expected a number, got null");
  error_is("{\"kt_worn\":true}", "kt_worn", 'n', "expected a number, got true");
  error_is("{\"latch\":1}", "latch", 'b', "setting \"latch\": expected true or false, got a number");
  error_is("{\"mode\":[\"a\"]}", "mode", 's', "setting \"mode\": expected a string, got an array");
  error_is("{\"mode\":{}}", "mode", 's', "expected a string, got an object");
  error_is("{\"mode\":\"12345678\"}", "mode", 's', "setting \"mode\": a string of 8 bytes, at most 7 fit");
  error_is("{\"mode\":\"a\\u0000b\"}", "mode", 's', "a string holding \\u0000");
  error_is("{\"x\":1e999}", "x", 'n', "setting \"x\": 1e999 is beyond a double");
  error_is("{\"x\":1,\"x\":2}", "x", 'n', "setting \"x\" appears twice");

  /* Malformed JSON: an error whatever key is asked, naming where. */
  error_is("{\"a\":1,}", "b", 'n', "settings: not one JSON object (at byte 7 of");
  error_is("{\"a\":1", "a", 'n', "settings: not one JSON object");
  error_is("{\"a\":\"unterminated}", "a", 's', "settings: not one JSON object (at byte 5");
  error_is("[1,2]", "a", 'n', "not one JSON object (at byte 0");
  error_is("{\"a\":1} x", "a", 'n', "not one JSON object (at byte 8");
  error_is("{\"a\":01}", "a", 'n', "not one JSON object");
  error_is("{\"a\":.5}", "a", 'n', "not one JSON object");
  error_is("{\"a\":tru}", "a", 'b', "not one JSON object");
  error_is("{\"a\":\"\\ud83d\"}", "a", 's', "not one JSON object"); /* half a surrogate pair */
  error_is("{\"a\":\"tab\there\"}", "a", 's', "not one JSON object"); /* a raw control character */
  error_is("", "a", 'n', "not one JSON object");
  r = armfault_setting_number(NULL, "a", &x, error, sizeof error);
  check(r == ARMFAULT_SETTING_ERROR && strstr(error, "no text") != NULL, "NULL text", error);
  {
    /* Nesting beyond 64 is refused, not recursed into without end. */
    char deep[400];
    int k;
    strcpy(deep, "{\"a\":");
    for (k = 0; k < 100; k++) strcat(deep, "[");
    for (k = 0; k < 100; k++) strcat(deep, "]");
    strcat(deep, "}");
    error_is(deep, "a", 'n', "not one JSON object");
  }

  /* Unknown keys. */
  {
    static const char* const known[] = {"window_s", "kt_worn"};
    r = armfault_setting_check_keys("{\"window_s\":1,\"kt_worn\":0.8}", known, 2, error, sizeof error);
    check(r == ARMFAULT_SETTING_FOUND, "known keys", error);
    r = armfault_setting_check_keys("{}", known, 2, error, sizeof error);
    check(r == ARMFAULT_SETTING_FOUND, "no keys", error);
    r = armfault_setting_check_keys("{\"window_s\":1,\"kt_wron\":0.8}", known, 2, error, sizeof error);
    check(r == ARMFAULT_SETTING_ERROR && strcmp(error, "unknown setting \"kt_wron\" (known: window_s, kt_worn)") == 0,
          "an unknown key is named with the known ones", error);
    /* A short error buffer: cut, NUL-terminated. */
    r = armfault_setting_check_keys("{\"kt_wron\":0.8}", known, 2, error, 12);
    check(r == ARMFAULT_SETTING_ERROR && strlen(error) == 11, "a short error buffer is cut and terminated", error);
  }

  /* The C locale's decimal comma does not change what a JSON number is. */
  if (setlocale(LC_NUMERIC, "de_DE.UTF-8") || setlocale(LC_NUMERIC, "fr_FR.UTF-8")) {
    number_is("{\"kt_worn\":0.85}", "kt_worn", 0.85);
    setlocale(LC_NUMERIC, "C");
  } else {
    printf("note: no de_DE or fr_FR locale here; the decimal-comma check was skipped\n");
  }

  printf("%d passed, %d failed\n", passed, failed);
  return failed ? 1 : 0;
}
