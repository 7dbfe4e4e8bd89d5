/* scene_private.h: what the scene reader's files share (private to scene/). */
/*
 * The scene reader is three files: scene_keys.c (the key table sp_keys[],
 * its keyword lists, the table's queries and `softpack keys`), scene.c
 * (loading with libcyaml, the values, `--set` overrides, the public entry
 * points) and scene_check.c (the checks of a loaded scene across keys).
 * This header is theirs alone: nothing outside src/scene/ includes it;
 * they include scene.h before it.
 */
#ifndef SP_SCENE_PRIVATE_H
#define SP_SCENE_PRIVATE_H

#include <cyaml/cyaml.h>
#include <stddef.h>

/* sp_scene (scene.h; not included here: scene.c includes this header, and
 * tools/check_includes.sh counts scene.h and scene.c as one module) */
typedef struct sp_scene sp_scene;

/** Sections of a scene file, in the order they are documented. */
typedef enum {
  SP_SEC_MESH,
  SP_SEC_MODEL,
  SP_SEC_TIME,
  SP_SEC_NOISE,
  SP_SEC_SOLVER,
  SP_SEC_OUTPUT,
  SP_SEC_DIVISION,
  SP_SEC_SOURCE,
  SP_SEC_LAYOUT,
  SP_SEC_SHAPE,
  SP_SEC_INITIAL,
  SP_SEC_CELLS, /**< a sequence of cell mappings, not a mapping of scalars */
  SP_SEC_LINEAGE, /**< a sequence of lineage entries, like cells */
  SP_SEC_ADHESION, /**< a sequence of named pairs' adhesion */
  SP_N_SECTIONS
} sp_section;

/** The sections before SP_SEC_CELLS are mappings of scalars, the rest
 *  sequences of mappings (one record each: sp_sequences[]). */
#define SP_N_MAPPINGS SP_SEC_CELLS
#define SP_N_SEQUENCES (SP_N_SECTIONS - SP_N_MAPPINGS)

extern const char *const sp_section_names[SP_N_SECTIONS];

/** 1 if @p section is a sequence (cells, lineage, adhesion), 0 if a mapping. */
static inline int is_sequence(sp_section section) { return section >= SP_N_MAPPINGS; }

/** Scalar type of a key as the user sees it. */
typedef enum {
  SP_KEY_FLOAT, /**< double */
  SP_KEY_INT,   /**< int (written as an integer-valued number, 1e6 is fine) */
  SP_KEY_UINT,  /**< unsigned */
  SP_KEY_BOOL,  /**< int 0/1, written true/false (yes/no, on/off) */
  SP_KEY_ENUM,  /**< int, written as one of a list of words */
  SP_KEY_PATH,  /**< char[SP_SCENE_PATH_MAX], a file name ("": none) */
  SP_KEY_NAME   /**< sp_cell_name: a cell's name ("": none; name_valid) */
} sp_key_type;

/** How one end of an allowed range is closed. */
typedef enum {
  SP_UNBOUNDED = 0, /**< no limit at this end */
  SP_INCLUSIVE,     /**< the limit itself is allowed */
  SP_EXCLUSIVE      /**< the limit itself is not allowed */
} sp_bound_kind;

typedef struct {
  sp_bound_kind kind;
  double value;
} sp_bound;

/** One key of the scene file. */
typedef struct {
  sp_section section;
  const char *name;
  sp_key_type type;
  size_t offset;   /**< into sp_scene, or into the record of a sequence
                        section (sp_scene_cell, sp_scene_lineage) */
  double fallback; /**< the default (enum/bool: the value of the word) */
  int required;    /**< 1: no default, the key must be given (sequences only) */
  sp_bound lower, upper;
  const cyaml_strval_t *words; /**< enum and bool: the accepted words */
  unsigned n_words;
  const char *unit;
  const char *meaning;
} sp_key;

/** The number of rows of sp_keys[] (scene_keys.c checks it at compile
 *  time: a key added there is counted here too). */
enum { SP_N_KEYS = 140 };

/** The key table, in the order of the documentation (scene_keys.c). */
extern const sp_key sp_keys[SP_N_KEYS];

/** mesh.type's words, by sp_mesh_kind. */
extern const cyaml_strval_t sp_mesh_words[];

/** Room for formatted keys and ranges, and for lists of them. */
enum { SP_TEXT = 256, SP_LIST_TEXT = 512 };

/* The table's queries (scene_keys.c) */

/** Position of @p key among the keys of its section: its raw slot. */
size_t sp_keys_slot(const sp_key *key);

/** The number of keys of @p section. */
size_t sp_keys_section_count(sp_section section);

/** The key named @p name (length @p len) in @p section, or NULL. */
const sp_key *sp_keys_find(sp_section section, const char *name, size_t len);

/** The section named @p name (length @p len), or SP_N_SECTIONS. */
sp_section sp_keys_find_section(const char *name, size_t len);

/** "model.kappa", or "cells[3].x", "lineage[0].cell" (cell < 0:
 *  "cells[i].x"), in @p buf. */
const char *sp_keys_path(const sp_key *key, int cell, char *buf, size_t size);

/** The keys of @p section, comma separated (only_required: those only). */
const char *sp_keys_section_list(sp_section section, int only_required, char *buf,
                                 size_t size);

/** The sections, comma separated. */
const char *sp_keys_sections(char *buf, size_t size);

/** The first word naming @p value (enum and bool keys). */
const char *sp_keys_word_of(const sp_key *key, double value);

/** What a key accepts, for messages: "a number > 0", "one of ad, hand". */
const char *sp_keys_expectation(const sp_key *key, char *buf, size_t size);

/** The checks of a loaded scene across keys (scene_check.c), in order: time
 *  and mesh, 2D or 3D, the initial fields' source, the cells inside Omega,
 *  the names and the lineage, the initial layout's size; @p where is the
 *  message prefix (the file). */
int sp_scene_validate(const sp_scene *scene, const char *where);

#endif
