/* ---- >>core_claims : who writes a solver's coupling arrays ---- */

#define FSDEM__CLAIMABLE 4 /* arrays of one solver that can be claimed (bits 0 .. 3) */

/* A solver's registry: the name of each array (by bit) and who holds it. */
struct fsdem_claims {
    const char *solver;                        /* "PIC", as messages name it */
    const char *const *array;                  /* the arrays' names, by bit */
    int count;                                 /* arrays (bits 0 .. count - 1) */
    const void *owner[FSDEM__CLAIMABLE];       /* NULL: free */
    char name[FSDEM__CLAIMABLE][48];
};

/* The registry of a new solver with `count` arrays, all free. */
static void fsdem__claims_init(fsdem_claims *c, const char *solver, const char *const *array, int count) {
    FSDEM_ASSERT(count <= FSDEM__CLAIMABLE);
    memset(c, 0, sizeof *c);
    c->solver = solver;
    c->array = array;
    c->count = count;
}

fsdem_result fsdem_claim(fsdem_claims *c, unsigned arrays, const void *owner, const char *name, char *msg, size_t size) {
    int k;
    if (!c || !owner || !name) return fsdem__reject(msg, size, "fsdem_claim: the registry, owner and name must be set");
    if (arrays >> c->count)
        return fsdem__reject(msg, size, "fsdem_claim: the %s has %d claimable arrays, bits 0x%x (got 0x%x)", c->solver, c->count,
                             (1u << c->count) - 1, arrays);
    for (k = 0; k < c->count; ++k)
        if ((arrays >> k & 1) && c->owner[k] && c->owner[k] != owner)
            return fsdem__reject(msg, size, "the %s's %s is claimed by %s (one writer per array: destroy it first)", c->solver,
                                 c->array[k], c->name[k]);
    for (k = 0; k < c->count; ++k)
        if (arrays >> k & 1) {
            c->owner[k] = owner;
            snprintf(c->name[k], sizeof c->name[k], "%s", name);
        }
    return FSDEM_OK;
}

void fsdem_release(fsdem_claims *c, unsigned arrays, const void *owner) {
    int k;
    if (!c) return;
    for (k = 0; k < c->count; ++k)
        if ((arrays >> k & 1) && c->owner[k] == owner) c->owner[k] = NULL;
}

const char *fsdem_claimant(const fsdem_claims *c, unsigned arrays) {
    int k;
    if (!c) return NULL;
    for (k = 0; k < c->count; ++k)
        if ((arrays >> k & 1) && c->owner[k]) return c->name[k];
    return NULL;
}
