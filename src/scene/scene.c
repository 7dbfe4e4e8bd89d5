/* scene.c: loading a scene file: libcyaml, values, `--set` overrides, the public entry points. */
/**
 * @file scene.c
 * @brief The scene file: a libcyaml schema built from the key table, the
 *        values' conversion and range checks, `--set` overrides.
 *
 * Everything a key is (section, name, type, where it lives in sp_scene,
 * default, allowed range, unit, meaning) is written once, in sp_keys[]
 * (scene_keys.c). The libcyaml schema, the defaults, the checks, the error
 * messages, the `--set` parser and the documentation table are all derived
 * from it. The checks across keys of a loaded scene are in scene_check.c.
 *
 * How libcyaml 1.3.1 is used, and why:
 * - Each section is loaded as an array of void * slots, one per key in table
 *   order; every key field is CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL, so a
 *   key absent from the file leaves its slot NULL and keeps its default.
 * - Numbers (float, int, uint keys) are loaded as strings and converted here
 *   with a strict parser. libcyaml 1.3.1's own scalar readers are lax: its
 *   FLOAT reader takes "1,5" as 1 and "2e-4s" as 2e-4, its INT reader takes
 *   "1.5" as 1, and its BOOL reader takes any word it does not know ("maybe")
 *   as true. A silently misread parameter is worse than a missing line
 *   number, which is all the string route costs (libcyaml reports lines only
 *   for what it rejects itself).
 * - Enums, and booleans (an enum of the YAML 1.1 words true/false, yes/no,
 *   on/off), are libcyaml ENUMs with CYAML_FLAG_STRICT: libcyaml rejects
 *   unknown words itself and reports the line.
 * - Errors: libcyaml logs a message ("Unexpected key: zz", "Invalid ENUM
 *   value: foo", "libyaml: did not find expected key", ...) followed by a
 *   backtrace, innermost first, of lines such as
 *   "  in mapping field 'linear' (line: 12, column: 11)" and
 *   "  in sequence entry '2' (line: 20, column: 5)" (1-based). A log_fn
 *   captures those lines; the backtrace is turned into a key path
 *   (solver.linear, cells[1].x) and the line of the innermost entry.
 * - `--set section.key=value` values are loaded by libcyaml with the very
 *   value schema the key has in the file and then go through the same
 *   conversion and range check, so a value means the same in both places.
 */
#include "scene/scene.h"

#include <cyaml/cyaml.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "public/error.h"
#include "scene/scene_private.h"

/** A sequence section: where its records and their count live in sp_scene,
 *  a record's size, and what one entry is called in messages. */
typedef struct {
  size_t records, count, size;
  const char *entry;
} sp_sequence;

static const sp_sequence sp_sequences[SP_N_SEQUENCES] = {
    {offsetof(sp_scene, cells), offsetof(sp_scene, n_cells), sizeof(sp_scene_cell), "a cell"},
    {offsetof(sp_scene, lineage), offsetof(sp_scene, n_lineage), sizeof(sp_scene_lineage),
     "a lineage entry"},
    {offsetof(sp_scene, adhesion), offsetof(sp_scene, n_adhesion), sizeof(sp_scene_adhesion),
     "an adhesion pair"}};

/** The sequence of a sequence section. */
static const sp_sequence *sequence_of(sp_section section) {
  return &sp_sequences[section - SP_N_MAPPINGS];
}

/** Record @p i of a sequence section of @p scene. */
static void *sequence_record(const sp_scene *scene, sp_section section, int i) {
  const sp_sequence *q = sequence_of(section);
  return *(char *const *)((const char *)scene + q->records) + (size_t)i * q->size;
}

static int sequence_count(const sp_scene *scene, sp_section section) {
  return *(const int *)((const char *)scene + sequence_of(section)->count);
}

/** Room for libcyaml's log lines. */
enum { SP_LOG_LINES = 16 };

/* ------------------------------------------------------------------------ */
/* Values: parse, check, store                                              */
/* ------------------------------------------------------------------------ */

/** Strict number: the whole text must be one finite strtod number. */
static int parse_number(const char *text, double *value) {
  char *end;
  if (!text || !*text) return 0;
  *value = strtod(text, &end);
  return end != text && *end == '\0' && isfinite(*value);
}

/** 1 if @p text is a cell name: 1 to SP_CELL_NAME_MAX - 1 letters, digits,
 *  '_', '.' or '-' (it goes into CSV columns and file names unquoted). */
static int name_valid(const char *text) {
  const size_t n = strlen(text);
  if (n == 0 || n >= SP_CELL_NAME_MAX) return 0;
  for (size_t i = 0; i < n; ++i) {
    const char c = text[i];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
          c == '_' || c == '.' || c == '-'))
      return 0;
  }
  return 1;
}

/** 1 if @p value is allowed for @p key (range; integers: integral). */
static int value_allowed(const sp_key *key, double value) {
  if (!isfinite(value)) return 0;
  if ((key->type == SP_KEY_INT || key->type == SP_KEY_UINT) &&
      value != floor(value))
    return 0;
  const sp_bound *lo = &key->lower, *hi = &key->upper;
  if (lo->kind == SP_INCLUSIVE && !(value >= lo->value)) return 0;
  if (lo->kind == SP_EXCLUSIVE && !(value > lo->value)) return 0;
  if (hi->kind == SP_INCLUSIVE && !(value <= hi->value)) return 0;
  if (hi->kind == SP_EXCLUSIVE && !(value < hi->value)) return 0;
  return 1;
}

/** Write @p value into the member of @p base (sp_scene or sp_scene_cell). */
static void store_value(void *base, const sp_key *key, double value) {
  char *member = (char *)base + key->offset;
  switch (key->type) {
  case SP_KEY_PATH:
  case SP_KEY_NAME: member[0] = '\0'; break; /* the default: none */
  case SP_KEY_FLOAT: *(double *)member = value; break;
  case SP_KEY_UINT: *(unsigned *)member = (unsigned)value; break;
  default: *(int *)member = (int)value; break; /* int, bool, enum */
  }
}

/** The member of @p base (sp_scene or sp_scene_cell) @p key names. */
static double load_value(const void *base, const sp_key *key) {
  const char *member = (const char *)base + key->offset;
  switch (key->type) {
  case SP_KEY_PATH:
  case SP_KEY_NAME: return 0.0; /* compared as text */
  case SP_KEY_FLOAT: return *(const double *)member;
  case SP_KEY_UINT: return *(const unsigned *)member;
  default: return *(const int *)member; /* int, bool, enum */
  }
}

/** 1 if @p key's values in @p a and @p b (sp_scene or records) differ:
 *  text compared as text, numbers bit for bit. */
static int values_differ(const void *a, const void *b, const sp_key *key) {
  if (key->type == SP_KEY_PATH || key->type == SP_KEY_NAME)
    return strcmp((const char *)a + key->offset, (const char *)b + key->offset) != 0;
  return memcmp(&(double){load_value(a, key)}, &(double){load_value(b, key)},
                sizeof(double)) != 0;
}

int sp_scene_first_difference(const sp_scene *a, const sp_scene *b,
                              int (*skip)(const char *key), char *buf, size_t size) {
  for (size_t i = 0; i < SP_N_KEYS; ++i) {
    const sp_key *key = &sp_keys[i];
    if (is_sequence(key->section)) continue;
    sp_keys_path(key, -1, buf, size);
    if (skip && skip(buf)) continue;
    if (values_differ(a, b, key)) return 1;
  }
  for (int s = SP_N_MAPPINGS; s < SP_N_SECTIONS; ++s) {
    const int n = sequence_count(a, (sp_section)s);
    if (n != sequence_count(b, (sp_section)s)) {
      snprintf(buf, size, "%s", sp_section_names[s]);
      if (skip && skip(buf)) continue;
      return 1;
    }
    for (int c = 0; c < n; ++c)
      for (size_t i = 0; i < SP_N_KEYS; ++i) {
        const sp_key *key = &sp_keys[i];
        if (key->section != (sp_section)s) continue;
        sp_keys_path(key, c + 1, buf, size);
        if (skip && skip(buf)) continue;
        if (values_differ(sequence_record(a, key->section, c),
                          sequence_record(b, key->section, c), key))
          return 1;
      }
  }
  return 0;
}

static void store_defaults(void *base, sp_section section) {
  for (size_t i = 0; i < SP_N_KEYS; ++i)
    if (sp_keys[i].section == section && !sp_keys[i].required)
      store_value(base, &sp_keys[i], sp_keys[i].fallback);
}

/**
 * @brief Convert one loaded slot (a string for numbers, an int for enum and
 *        bool keys), check it and store it.
 * @param where message prefix: the file, or "--set ..."
 * @param cell the cell index for cells keys, else -1
 */
static int store_slot(void *base, const sp_key *key, const void *slot,
                      const char *where, int cell) {
  char path[SP_TEXT], expected[SP_LIST_TEXT];
  double value;
  const char *text = NULL;
  if (key->type == SP_KEY_NAME) {
    text = slot;
    if (!name_valid(text))
      return sp_error_set(SP_ERR_INPUT, "%s: %s: expected %s, got '%s'", where,
                          sp_keys_path(key, cell, path, sizeof path),
                          sp_keys_expectation(key, expected, sizeof expected), text);
    strcpy((char *)base + key->offset, text);
    return SP_OK;
  }
  if (key->type == SP_KEY_PATH) {
    text = slot;
    if (strlen(text) >= SP_SCENE_PATH_MAX)
      return sp_error_set(SP_ERR_INPUT, "%s: %s: expected %s, got one of %zu", where,
                          sp_keys_path(key, cell, path, sizeof path),
                          sp_keys_expectation(key, expected, sizeof expected), strlen(text));
    strcpy((char *)base + key->offset, text);
    return SP_OK;
  }
  if (key->type == SP_KEY_BOOL || key->type == SP_KEY_ENUM) {
    value = *(const int *)slot;
  } else {
    text = slot;
    if (!parse_number(text, &value))
      return sp_error_set(SP_ERR_INPUT, "%s: %s: expected %s, got '%s'", where,
                          sp_keys_path(key, cell, path, sizeof path),
                          sp_keys_expectation(key, expected, sizeof expected), text);
  }
  if (!value_allowed(key, value))
    return sp_error_set(SP_ERR_INPUT, "%s: %s: expected %s, got %s", where,
                        sp_keys_path(key, cell, path, sizeof path),
                        sp_keys_expectation(key, expected, sizeof expected),
                        text ? text : sp_keys_word_of(key, value));
  store_value(base, key, value);
  return SP_OK;
}

/* ------------------------------------------------------------------------ */
/* The libcyaml schema, built from the table                                */
/* ------------------------------------------------------------------------ */

/** What libcyaml loads: per mapping section an array of key slots (NULL =
 *  absent), and per sequence section (cells, lineage) its entries as
 *  consecutive arrays of key slots. */
typedef struct {
  void **section[SP_N_MAPPINGS];
  void **entries[SP_N_SEQUENCES];
  uint32_t n_entries[SP_N_SEQUENCES];
} sp_raw_scene;

/** The schema. It points into itself: build it in place, never copy it. */
typedef struct {
  /* every section's key fields, each list closed by an end entry */
  cyaml_schema_field_t key_fields[SP_N_KEYS + SP_N_SECTIONS];
  cyaml_schema_field_t section_fields[SP_N_SECTIONS + 1];
  cyaml_schema_value_t entry[SP_N_SEQUENCES]; /**< one entry of a sequence */
  cyaml_schema_value_t top;
} sp_schema;

/** The value schema of one key (a pointer: the slot receives it). */
static cyaml_schema_value_t key_value_schema(const sp_key *key) {
  cyaml_schema_value_t v;
  memset(&v, 0, sizeof v);
  v.flags = CYAML_FLAG_POINTER;
  switch (key->type) {
  case SP_KEY_BOOL:
    v.flags |= CYAML_FLAG_CASE_INSENSITIVE; /* True, YES as YAML allows */
    /* fall through */
  case SP_KEY_ENUM:
    v.type = CYAML_ENUM;
    v.flags |= CYAML_FLAG_STRICT; /* words only: no bare numbers */
    v.data_size = sizeof(int);
    v.enumeration.strings = key->words;
    v.enumeration.count = key->n_words;
    break;
  default: /* numbers: loaded as text, see the file comment */
    v.type = CYAML_STRING;
    v.data_size = sizeof(char *);
    v.string.min = 0;
    v.string.max = CYAML_UNLIMITED;
  }
  return v;
}

static void build_schema(sp_schema *schema) {
  memset(schema, 0, sizeof *schema);
  size_t n = 0;
  for (int s = 0; s < SP_N_SECTIONS; ++s) {
    cyaml_schema_field_t *first = &schema->key_fields[n];
    size_t slots = 0;
    for (size_t i = 0; i < SP_N_KEYS; ++i) {
      const sp_key *key = &sp_keys[i];
      if (key->section != (sp_section)s) continue;
      cyaml_schema_field_t *f = &schema->key_fields[n++];
      f->key = key->name;
      f->data_offset = (uint32_t)(slots++ * sizeof(void *));
      f->value = key_value_schema(key);
      if (!key->required) f->value.flags |= CYAML_FLAG_OPTIONAL;
    }
    ++n; /* the zeroed end entry */
    cyaml_schema_field_t *sf = &schema->section_fields[s];
    sf->key = sp_section_names[s];
    if (is_sequence((sp_section)s)) {
      const int q = s - SP_N_MAPPINGS;
      cyaml_schema_value_t *entry = &schema->entry[q];
      entry->type = CYAML_MAPPING;
      entry->flags = CYAML_FLAG_DEFAULT;
      entry->data_size = (uint32_t)(slots * sizeof(void *));
      entry->mapping.fields = first;
      sf->data_offset = (uint32_t)(offsetof(sp_raw_scene, entries) + (size_t)q * sizeof(void **));
      sf->count_offset =
          (uint32_t)(offsetof(sp_raw_scene, n_entries) + (size_t)q * sizeof(uint32_t));
      sf->count_size = sizeof(uint32_t);
      sf->value.type = CYAML_SEQUENCE;
      /* cells: absent or empty is reported by sp_scene_load itself */
      sf->value.flags = CYAML_FLAG_POINTER_NULL | CYAML_FLAG_OPTIONAL;
      sf->value.data_size = entry->data_size;
      sf->value.sequence.entry = entry;
      sf->value.sequence.min = 0;
      sf->value.sequence.max = CYAML_UNLIMITED;
    } else {
      sf->data_offset = (uint32_t)(offsetof(sp_raw_scene, section) +
                                   (size_t)s * sizeof(void **));
      sf->value.type = CYAML_MAPPING;
      /* a section left empty ("model:") just keeps the defaults */
      sf->value.flags = CYAML_FLAG_POINTER_NULL | CYAML_FLAG_OPTIONAL;
      sf->value.data_size = (uint32_t)(slots * sizeof(void *));
      sf->value.mapping.fields = first;
    }
  }
  schema->top.type = CYAML_MAPPING;
  schema->top.flags = CYAML_FLAG_POINTER;
  schema->top.data_size = sizeof(sp_raw_scene);
  schema->top.mapping.fields = schema->section_fields;
}

/* ------------------------------------------------------------------------ */
/* libcyaml errors -> one message naming the key                            */
/* ------------------------------------------------------------------------ */

/** The log lines libcyaml wrote during one load. */
typedef struct {
  char line[SP_LOG_LINES][SP_TEXT];
  int n;
} sp_cyaml_log;

static void capture_log(cyaml_log_t level, void *ctx, const char *fmt,
                        va_list args) {
  sp_cyaml_log *log = ctx;
  if (level < CYAML_LOG_ERROR || log->n >= SP_LOG_LINES) return;
  char *line = log->line[log->n++];
  vsnprintf(line, SP_TEXT, fmt, args);
  line[strcspn(line, "\n")] = '\0';
}

static cyaml_config_t cyaml_config(sp_cyaml_log *log) {
  cyaml_config_t config;
  memset(&config, 0, sizeof config);
  config.log_fn = capture_log;
  config.log_ctx = log;
  config.mem_fn = cyaml_mem;
  config.log_level = CYAML_LOG_ERROR;
  config.flags = CYAML_CFG_DEFAULT; /* unknown keys are errors */
  return config;
}

/** libcyaml's own message (its first log line without "Load: "). */
static const char *cyaml_message(const sp_cyaml_log *log, cyaml_err_t err) {
  static const char load_tag[] = "Load: ";
  const char *message = log->n ? log->line[0] : cyaml_strerror(err);
  if (strncmp(message, load_tag, sizeof load_tag - 1) == 0)
    message += sizeof load_tag - 1;
  return message;
}

/** Where libcyaml stopped: key path from the backtrace and its line. */
typedef struct {
  char path[SP_TEXT];
  unsigned line; /**< 0: unknown */
} sp_yaml_where;

/**
 * @brief Turn the captured backtrace into a key path ("solver.linear",
 *        "cells[1].x") and the line of its innermost entry.
 * @param drop_innermost_field for a missing field libcyaml's innermost entry
 *        is the last field it read in that mapping, not the missing one
 */
static void backtrace_where(const sp_cyaml_log *log, int drop_innermost_field,
                            sp_yaml_where *where) {
  static const char field_tag[] = "in mapping field '";
  static const char entry_tag[] = "in sequence entry '";
  static const char line_tag[] = "(line: ";
  int innermost = -1, first = log->n;
  where->path[0] = '\0';
  where->line = 0;
  for (int i = 0; i < log->n; ++i)
    if (strstr(log->line[i], "Backtrace:")) {
      first = i + 1;
      break;
    }
  if (drop_innermost_field && first < log->n &&
      strstr(log->line[first], field_tag))
    ++first;
  for (int i = log->n - 1; i >= first; --i) { /* outermost first */
    const char *l = log->line[i], *name;
    size_t used = strlen(where->path);
    if ((name = strstr(l, field_tag))) {
      name += sizeof field_tag - 1;
      snprintf(where->path + used, sizeof where->path - used, "%s%.*s",
               used ? "." : "", (int)strcspn(name, "'"), name);
    } else if ((name = strstr(l, entry_tag))) {
      /* libcyaml counts entries from 1, the messages from 0 */
      long entry = strtol(name + sizeof entry_tag - 1, NULL, 10);
      snprintf(where->path + used, sizeof where->path - used, "[%ld]",
               entry - 1);
    }
    innermost = i;
  }
  if (innermost >= 0) {
    const char *l = strstr(log->line[innermost], line_tag);
    if (l) where->line = (unsigned)strtoul(l + sizeof line_tag - 1, NULL, 10);
  }
}

/** "scene.yaml:12" or "scene.yaml" when the line is unknown. */
static const char *file_line(const char *file, unsigned line, char *buf,
                             size_t size) {
  if (line)
    snprintf(buf, size, "%s:%u", file, line);
  else
    snprintf(buf, size, "%s", file);
  return buf;
}

/** What belongs at @p path ("", "model", "cells", "cells[2]",
 *  "model.kappa", "cells[2].x"), for messages. */
static const char *path_expectation(const char *path, char *buf,
                                    size_t size) {
  char list[SP_LIST_TEXT];
  size_t head = strcspn(path, ".[");
  sp_section s = sp_keys_find_section(path, head);
  if (!*path) {
    snprintf(buf, size, "a mapping of sections (%s)",
             sp_keys_sections(list, sizeof list));
  } else if (s == SP_N_SECTIONS) {
    snprintf(buf, size, "a known section");
  } else if (path[head] == '\0') {
    if (is_sequence(s))
      snprintf(buf, size, "a sequence of %s entries, each a mapping of %s", sp_section_names[s],
               sp_keys_section_list(s, 0, list, sizeof list));
    else
      snprintf(buf, size, "a mapping of %s keys (%s)", sp_section_names[s],
               sp_keys_section_list(s, 0, list, sizeof list));
  } else {
    const char *name = strrchr(path, '.');
    const sp_key *key = name ? sp_keys_find(s, name + 1, strlen(name + 1)) : NULL;
    if (key)
      sp_keys_expectation(key, buf, size);
    else /* a cells entry itself, "cells[2]" */
      snprintf(buf, size, "a mapping of %s",
               sp_keys_section_list(s, 0, list, sizeof list));
  }
  return buf;
}

/** The message for a failed cyaml_load_*; returns the error code. */
static int report_cyaml_error(const char *file, cyaml_err_t err,
                              const sp_cyaml_log *log) {
  static const char key_tag[] = "Unexpected key: ";
  static const char missing_tag[] = "Missing required mapping field: ";
  static const char seen_tag[] = "Mapping field already seen";
  char at[SP_TEXT + SP_TEXT], expected[SP_LIST_TEXT], list[SP_LIST_TEXT];
  sp_yaml_where where;
  const char *message = cyaml_message(log, err);

  if (err == CYAML_ERR_OOM)
    return sp_error_set(SP_ERR_MEMORY, "%s: out of memory while loading",
                        file);
  if (err == CYAML_ERR_INVALID_KEY) {
    /* the innermost backtrace entry is the enclosing mapping; libcyaml's
     * line there is that of the previous value, so no line is given */
    backtrace_where(log, 0, &where);
    const char *name = strstr(message, key_tag);
    name = name ? name + sizeof key_tag - 1 : "?";
    if (!where.path[0])
      return sp_error_set(SP_ERR_INPUT,
                          "%s: %s: unknown section; the sections are %s "
                          "(libcyaml: %s)",
                          file, name, sp_keys_sections(list, sizeof list),
                          message);
    sp_section s = sp_keys_find_section(where.path, strcspn(where.path, ".["));
    return sp_error_set(SP_ERR_INPUT,
                        "%s: %s.%s: unknown key; %s has %s (libcyaml: %s)",
                        file, where.path, name,
                        s < SP_N_SECTIONS && is_sequence(s) ? sequence_of(s)->entry
                                                            : where.path,
                        s < SP_N_SECTIONS
                            ? sp_keys_section_list(s, 0, list, sizeof list)
                            : "no such key",
                        message);
  }
  if (err == CYAML_ERR_MAPPING_FIELD_MISSING) {
    backtrace_where(log, 1, &where);
    const char *name = strstr(message, missing_tag);
    name = name ? name + sizeof missing_tag - 1 : "?";
    sp_section s = sp_keys_find_section(where.path, strcspn(where.path, ".["));
    if (s == SP_N_SECTIONS || !is_sequence(s)) s = SP_SEC_CELLS;
    return sp_error_set(SP_ERR_INPUT,
                        "%s: %s%s%s: missing; every %s needs %s "
                        "(libcyaml: %s)",
                        file_line(file, where.line, at, sizeof at),
                        where.path, where.path[0] ? "." : "", name,
                        sequence_of(s)->entry + 2, /* "cell", "lineage entry" */
                        sp_keys_section_list(s, 1, list, sizeof list), message);
  }
  backtrace_where(log, 0, &where);
  if (err == CYAML_ERR_LIBYAML_PARSER) {
    /* libcyaml knows only where the last good event was, not the error */
    if (where.path[0])
      return sp_error_set(SP_ERR_INPUT,
                          "%s: malformed YAML in %s, after line %u: %s",
                          file, where.path, where.line, message);
    return sp_error_set(SP_ERR_INPUT, "%s: malformed YAML: %s", file,
                        message);
  }
  if (strncmp(message, seen_tag, sizeof seen_tag - 1) == 0)
    return sp_error_set(SP_ERR_INPUT, "%s: %s: given twice (libcyaml: %s)",
                        file_line(file, where.line, at, sizeof at),
                        where.path, message);
  const char *path = where.path[0] ? where.path : "top level";
  file_line(file, where.line, at, sizeof at);
  if (err == CYAML_ERR_INVALID_VALUE || err == CYAML_ERR_UNEXPECTED_EVENT)
    return sp_error_set(SP_ERR_INPUT, "%s: %s: expected %s (libcyaml: %s)",
                        at, path,
                        path_expectation(where.path, expected,
                                         sizeof expected),
                        message);
  if (err == CYAML_ERR_INVALID_ALIAS || err == CYAML_ERR_ALIAS)
    return sp_error_set(SP_ERR_INPUT, "%s: %s: bad YAML alias (libcyaml: %s)",
                        at, path, message);
  if (err == CYAML_ERR_INTERNAL_ERROR) {
    /* libcyaml 1.3.1 says "internal error" for an event its state has no
     * handler for, which input can cause: a key that is itself a mapping
     * or a sequence, "{x: 1, y}: 2" (tests/scenes/fuzz/). The backtrace's
     * innermost field is the last one read, not the bad key. */
    backtrace_where(log, 1, &where);
    path = where.path[0] ? where.path : "top level";
    return sp_error_set(SP_ERR_INPUT,
                        "%s: %s: expected %s; libcyaml cannot read what follows "
                        "there (a key that is a mapping or a sequence?) (libcyaml: %s)",
                        file_line(file, where.line, at, sizeof at), path,
                        path_expectation(where.path, expected, sizeof expected),
                        cyaml_strerror(err));
  }
  /* anything else is a schema or library problem, not the user's */
  return sp_error_set(SP_ERR_INTERNAL, "%s: libcyaml failed (%s): %s", file,
                      cyaml_strerror(err), message);
}

/* ------------------------------------------------------------------------ */
/* Loading                                                                  */
/* ------------------------------------------------------------------------ */

/** Read the whole file (libcyaml's own open gives no reason on failure). */
static int read_file(const char *path, char **text, size_t *len) {
  FILE *f = fopen(path, "rb");
  SP_CHECK(f, SP_ERR_INPUT, "%s: cannot open the scene file: %s", path,
           strerror(errno));
  size_t size = 0, capacity = BUFSIZ;
  char *buf = malloc(capacity);
  while (buf) {
    size += fread(buf + size, 1, capacity - size, f);
    if (size < capacity) break;
    char *bigger = realloc(buf, 2 * capacity);
    if (!bigger) {
      free(buf);
      buf = NULL;
    } else {
      buf = bigger;
      capacity *= 2;
    }
  }
  int failed = !buf || ferror(f);
  int err = errno;
  fclose(f);
  if (!buf)
    return sp_error_set(SP_ERR_MEMORY, "%s: out of memory reading the file",
                        path);
  if (failed) {
    free(buf);
    return sp_error_set(SP_ERR_INPUT, "%s: cannot read the scene file: %s",
                        path, strerror(err));
  }
  *text = buf;
  *len = size;
  return SP_OK;
}

/** Defaults, then the values of the loaded file. */
static int apply_raw(sp_scene *scene, const sp_raw_scene *raw,
                     const char *file) {
  for (size_t i = 0; i < SP_N_KEYS; ++i) {
    const sp_key *key = &sp_keys[i];
    void **slots = is_sequence(key->section) ? NULL : raw->section[key->section];
    if (slots && slots[sp_keys_slot(key)])
      SP_CALL(store_slot(scene, key, slots[sp_keys_slot(key)], file, -1));
  }
  /* file names in the scene are relative to the scene file's directory */
  const char *slash = strrchr(file, '/');
  for (size_t i = 0; slash && i < SP_N_KEYS; ++i) {
    const sp_key *key = &sp_keys[i];
    char *value = (char *)scene + key->offset;
    if (key->type != SP_KEY_PATH || !value[0] || value[0] == '/') continue;
    char joined[SP_SCENE_PATH_MAX + 1];
    const int n = snprintf(joined, sizeof joined, "%.*s/%s", (int)(slash - file), file, value);
    char path[SP_TEXT];
    SP_CHECK(n > 0 && n < SP_SCENE_PATH_MAX, SP_ERR_INPUT,
             "%s: %s: the file name with the scene's directory is longer than %d characters",
             file, sp_keys_path(key, -1, path, sizeof path), SP_SCENE_PATH_MAX - 1);
    memcpy(value, joined, (size_t)n + 1);
  }
  /* libcyaml loads "cells: []", "cells:" and no cells key alike; none is
   * right only with initial.from or initial.label_image (check_initial) */
  for (int s = SP_N_MAPPINGS; s < SP_N_SECTIONS; ++s) {
    const sp_sequence *q = sequence_of((sp_section)s);
    const uint32_t n = raw->n_entries[s - SP_N_MAPPINGS];
    char *records = calloc(n ? n : 1, q->size);
    SP_CHECK(records, SP_ERR_MEMORY, "%s: out of memory for %u %s entries", file, n,
             sp_section_names[s]);
    *(char **)((char *)scene + q->records) = records;
    *(int *)((char *)scene + q->count) = (int)n;
    const size_t n_keys = sp_keys_section_count((sp_section)s);
    for (uint32_t c = 0; c < n; ++c) {
      void **slots = raw->entries[s - SP_N_MAPPINGS] + (size_t)c * n_keys;
      void *record = records + (size_t)c * q->size;
      store_defaults(record, (sp_section)s);
      for (size_t i = 0; i < SP_N_KEYS; ++i) {
        const sp_key *key = &sp_keys[i];
        if (key->section == (sp_section)s && slots[sp_keys_slot(key)])
          SP_CALL(store_slot(record, key, slots[sp_keys_slot(key)], file, (int)c));
      }
    }
  }
  return SP_OK;
}

/** The values of a scene file's text; @p name is the file in messages. */
static int load_text(sp_scene *scene, const char *name, const char *text,
                     size_t len) {
  sp_schema schema;
  build_schema(&schema);
  sp_cyaml_log log = {.n = 0};
  cyaml_config_t config = cyaml_config(&log);
  sp_raw_scene *raw = NULL;
  cyaml_err_t err = CYAML_OK;
  if (len > 0)
    err = cyaml_load_data((const uint8_t *)text, len, &config, &schema.top,
                          (cyaml_data_t **)&raw, NULL);
  if (err != CYAML_OK) return report_cyaml_error(name, err, &log);
  /* an empty file, or only comments: libcyaml succeeds with no data */
  SP_CHECK(raw, SP_ERR_INPUT,
           "%s: cells: missing; the file holds no YAML document (empty or "
           "only comments) and a scene needs at least one cell",
           name);
  int rc = apply_raw(scene, raw, name);
  cyaml_free(&config, &schema.top, raw, 0);
  return rc;
}

static int load_file(sp_scene *scene, const char *path) {
  char *text = NULL;
  size_t len = 0;
  SP_CALL(read_file(path, &text, &len));
  int rc = load_text(scene, path, text, len);
  free(text);
  return rc;
}

/** Apply one "section.key=value" override. */
static int apply_override(sp_scene *scene, const char *arg) {
  char where[SP_TEXT + SP_TEXT], list[SP_LIST_TEXT], expected[SP_LIST_TEXT];
  snprintf(where, sizeof where, "--set %s", arg);
  const char *eq = strchr(arg, '=');
  SP_CHECK(eq, SP_ERR_INPUT,
           "%s: expected section.key=value, but '%s' has no '='", where, arg);
  size_t name_len = (size_t)(eq - arg);
  const char *dot = memchr(arg, '.', name_len);
  SP_CHECK(dot, SP_ERR_INPUT,
           "%s: %.*s: expected section.key=value (no section given); the "
           "sections are %s",
           where, (int)name_len, arg, sp_keys_sections(list, sizeof list));
  sp_section s = sp_keys_find_section(arg, (size_t)(dot - arg));
  SP_CHECK(s != SP_N_SECTIONS, SP_ERR_INPUT,
           "%s: %.*s: unknown section; the sections are %s", where,
           (int)name_len, arg, sp_keys_sections(list, sizeof list));
  SP_CHECK(!is_sequence(s), SP_ERR_INPUT,
           "%s: %.*s: %s cannot be set from the command line; edit the "
           "%s list of the scene file",
           where, (int)name_len, arg, sp_section_names[s], sp_section_names[s]);
  const sp_key *key = sp_keys_find(s, dot + 1, (size_t)(eq - dot - 1));
  SP_CHECK(key, SP_ERR_INPUT, "%s: %.*s: unknown key; %s has %s", where,
           (int)name_len, arg, sp_section_names[s],
           sp_keys_section_list(s, 0, list, sizeof list));

  /* the value is read by libcyaml as a one-scalar YAML document with the
   * key's own value schema: the same words and text as in a file */
  char path[SP_TEXT];
  sp_keys_path(key, -1, path, sizeof path);
  cyaml_schema_value_t schema = key_value_schema(key);
  sp_cyaml_log log = {.n = 0};
  cyaml_config_t config = cyaml_config(&log);
  void *value = NULL;
  const char *text = eq + 1;
  cyaml_err_t err = cyaml_load_data((const uint8_t *)text, strlen(text),
                                    &config, &schema, &value, NULL);
  if (err == CYAML_ERR_OOM)
    return sp_error_set(SP_ERR_MEMORY, "%s: out of memory", where);
  SP_CHECK(err == CYAML_OK, SP_ERR_INPUT,
           "%s: %s: expected %s, got '%s' (libcyaml: %s)", where, path,
           sp_keys_expectation(key, expected, sizeof expected), text,
           cyaml_message(&log, err));
  SP_CHECK(value, SP_ERR_INPUT, "%s: %s: expected %s, got nothing", where,
           path, sp_keys_expectation(key, expected, sizeof expected));
  int rc = store_slot(scene, key, value, where, -1);
  cyaml_free(&config, &schema, value, 0);
  return rc;
}

/* ------------------------------------------------------------------------ */
/* Public functions                                                         */
/* ------------------------------------------------------------------------ */

/** Everything sp_scene_load does to a zeroed scene, from the file @p path
 *  or, when @p text is not NULL, from @p text standing for it; the caller
 *  frees the scene on failure, so this may return from anywhere. */
static int fill_scene(sp_scene *scene, const char *path, const char *text,
                      size_t len, int n_set, const char *const *set) {
  for (int s = 0; s < SP_N_MAPPINGS; ++s) store_defaults(scene, (sp_section)s);
  SP_CALL(text ? load_text(scene, path, text, len) : load_file(scene, path));
  for (int i = 0; i < n_set; ++i) SP_CALL(apply_override(scene, set[i]));
  /* a clash may come from an override: say so in the prefix */
  char where[SP_TEXT + SP_TEXT];
  snprintf(where, sizeof where, "%s%s", path,
           n_set ? " (with its --set overrides)" : "");
  return sp_scene_validate(scene, where); /* scene_check.c */
}

int sp_scene_cell_is_turned(const sp_scene_cell *cell) {
  return !isnan(cell->axis[0]) || !isnan(cell->axis[1]) || !isnan(cell->axis[2]);
}

void sp_scene_cell_frame(const sp_scene_cell *cell, double R[3][3]) {
  for (int d = 0; d < 3; ++d)
    for (int j = 0; j < 3; ++j) R[d][j] = d == j;
  if (!sp_scene_cell_is_turned(cell)) return;
  double a[3], norm = 0;
  for (int d = 0; d < 3; ++d) {
    a[d] = isnan(cell->axis[d]) ? 0.0 : cell->axis[d];
    norm = hypot(norm, a[d]);
  }
  for (int d = 0; d < 3; ++d) a[d] /= norm; /* (not 0: check_cell_axis) */
  if (a[0] <= -1.0) { /* -x: a half turn about z */
    R[0][0] = R[1][1] = -1;
    return;
  }
  /* Rodrigues: R = I + [v]x + [v]x^2 / (1 + c), v = x cross a, c = x . a */
  const double v[3] = {0, -a[2], a[1]}, f = 1 / (1 + a[0]);
  const double K[3][3] = {{0, -v[2], v[1]}, {v[2], 0, -v[0]}, {-v[1], v[0], 0}};
  for (int d = 0; d < 3; ++d)
    for (int j = 0; j < 3; ++j) {
      double kk = 0;
      for (int m = 0; m < 3; ++m) kk += K[d][m] * K[m][j];
      R[d][j] += K[d][j] + f * kk;
    }
}

double sp_scene_cell_extent(const sp_scene_cell *cell, int dim, int d) {
  if (!sp_scene_cell_is_turned(cell)) return sp_scene_cell_semi_axis(cell, d);
  double R[3][3], e = 0;
  sp_scene_cell_frame(cell, R);
  for (int j = 0; j < dim; ++j) e = hypot(e, R[d][j] * sp_scene_cell_semi_axis(cell, j));
  return e;
}

void sp_scene_cell_point(const sp_scene_cell *cell, int dim, const double *centre,
                         const double *local, double *out) {
  if (!sp_scene_cell_is_turned(cell)) {
    for (int d = 0; d < dim; ++d) out[d] = centre[d] + local[d];
    return;
  }
  double R[3][3];
  sp_scene_cell_frame(cell, R);
  for (int d = 0; d < dim; ++d) {
    out[d] = centre[d];
    for (int j = 0; j < dim; ++j) out[d] += R[d][j] * local[j];
  }
}

double sp_scene_cell_semi_axis(const sp_scene_cell *cell, int d) {
  const double given = d == 0 ? cell->semi_x : d == 1 ? cell->semi_y : cell->semi_z;
  return isnan(given) ? cell->radius : given;
}

int sp_scene_cell_is_ellipsoid(const sp_scene_cell *cell) {
  return !isnan(cell->semi_x) || !isnan(cell->semi_y) || !isnan(cell->semi_z);
}

int sp_scene_dim(const sp_scene *scene) {
  return scene->mesh.type == SP_MESH_BOX || scene->mesh.type == SP_MESH_ELLIPSOID ? 3 : 2;
}

int sp_scene_read_file(const char *path, char **text, size_t *len) {
  return read_file(path, text, len);
}

static int load_scene(const char *path, const char *text, size_t len,
                      int n_set, const char *const *set, sp_scene **out) {
  SP_CHECK(path && out && n_set >= 0 && (n_set == 0 || set), SP_ERR_INTERNAL,
           "sp_scene_load: bad arguments");
  *out = NULL;
  sp_scene *scene;
  SP_ALLOC(scene, 1);
  int rc = fill_scene(scene, path, text, len, n_set, set);
  if (rc != SP_OK) {
    sp_scene_destroy(&scene);
    return rc;
  }
  *out = scene;
  return SP_OK;
}

int sp_scene_load(const char *path, int n_set, const char *const *set,
                  sp_scene **out) {
  return load_scene(path, NULL, 0, n_set, set, out);
}

int sp_scene_load_text(const char *name, const char *text, size_t len,
                       int n_set, const char *const *set, sp_scene **out) {
  SP_CHECK(text || len == 0, SP_ERR_INTERNAL, "sp_scene_load_text: no text");
  return load_scene(name, text ? text : "", len, n_set, set, out);
}

double sp_scene_interface_width(const sp_scene *scene) {
  return sqrt(scene->model.kappa / (2.0 * scene->model.alpha));
}

void sp_scene_destroy(sp_scene **scene) {
  if (!scene || !*scene) return;
  free((*scene)->cells);
  free((*scene)->lineage);
  free((*scene)->adhesion);
  free(*scene);
  *scene = NULL;
}
