/*
 * test_pdict.c - the parameter dictionary (io/pdict.h): typed getters with
 * defaults and ranges and their messages, marks and the one "unknown
 * parameter" warning per parameter, duplicates, and the cJSON adapter
 * (numbers kept as read, the element of a list named in a message).
 */
#include "io/pdict.h"
#include "test.h"
#include "warnings.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <string.h>

static pd_entry num(const char *name, double v) { return (pd_entry){.name = name, .kind = PD_NUMBER, .num = v}; }

int main(void)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log w;
    warning_log_attach(ctx, &w);

    /* typed getters: defaults when absent, values when present */
    pdict d;
    pd_init(&d, ctx, NULL, NULL, "thing", true);
    const double rgb[3] = {0.25, 0.5, 1.0};
    pd_entry e = num("f", 0.5);
    REQUIRE(pd_add(&d, &e) == PK_OK);
    e = (pd_entry){.name = "c", .kind = PD_NUMBERS, .nums = rgb, .n = 3, .first_other = 3};
    REQUIRE(pd_add(&d, &e) == PK_OK);
    e = num("i", 7);
    REQUIRE(pd_add(&d, &e) == PK_OK);
    e = (pd_entry){.name = "b", .kind = PD_BOOL, .b = true};
    REQUIRE(pd_add(&d, &e) == PK_OK);
    e = (pd_entry){.name = "s", .kind = PD_STRING, .str = "hello"};
    REQUIRE(pd_add(&d, &e) == PK_OK);
    float f = 0.0f;
    vec3 v = v3s(0.0f);
    int i = 0;
    bool b = false;
    const char *str = NULL;
    CHECK(pd_float(&d, "f", 2.0f, PD_UNIT, &f) == PK_OK && f == 0.5f);
    CHECK(pd_float(&d, "absent", 2.0f, PD_UNIT, &f) == PK_OK && f == 2.0f); /* the default is not range-checked */
    CHECK(pd_vec3(&d, "c", v3s(9.0f), PD_V_REFLECTANCE, &v) == PK_OK && v.x == 0.25f && v.y == 0.5f && v.z == 1.0f);
    CHECK(pd_int(&d, "i", 0, 0, 10, &i) == PK_OK && i == 7);
    CHECK(pd_bool(&d, "b", false, &b) == PK_OK && b);
    CHECK(pd_string(&d, "s", NULL, &str) == PK_OK && str && strcmp(str, "hello") == 0);
    CHECK(pd_report_unused(&d) == PK_OK && w.count == 0); /* all were read */

    /* ranges, each with its message, latched in the context */
    CHECK(pd_float(&d, "i", 0.0f, PD_UNIT, &f) == PK_ERR_PARSE);
    CHECKF(strcmp(pk_context_error(ctx), "thing: i: must be in 0..1") == 0, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    CHECK(pd_int(&d, "i", 0, 0, 5, &i) == PK_ERR_LIMIT); /* above the range: a limit */
    CHECKF(strcmp(pk_context_error(ctx), "thing: i: must be an integer in 0..5") == 0, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    CHECK(pd_int(&d, "f", 0, 0, 5, &i) == PK_ERR_PARSE);
    CHECK(strcmp(pk_context_error(ctx), "thing: f: must be an integer") == 0);
    pk_context_clear_error(ctx);
    CHECK(pd_vec3(&d, "f", v3s(0.0f), PD_V_ANY, &v) == PK_ERR_PARSE);
    CHECK(strcmp(pk_context_error(ctx), "thing: f: must be an array of 3 numbers") == 0);
    pk_context_clear_error(ctx);
    CHECK(pd_bool(&d, "s", false, &b) == PK_ERR_PARSE);
    CHECK(strcmp(pk_context_error(ctx), "thing: s: must be true or false") == 0);
    pk_context_clear_error(ctx);
    e = num("nan", NAN);
    REQUIRE(pd_set(&d, &e) == PK_OK);
    CHECK(pd_float(&d, "nan", 0.0f, PD_ANY, &f) == PK_ERR_PARSE);
    CHECK(strcmp(pk_context_error(ctx), "thing: nan: must be a finite number") == 0);
    pk_context_clear_error(ctx);
    e = num("neg", -1.0);
    REQUIRE(pd_set(&d, &e) == PK_OK);
    CHECK(pd_float(&d, "neg", 0.0f, PD_NONNEG, &f) == PK_ERR_PARSE);
    CHECK(strcmp(pk_context_error(ctx), "thing: neg: must not be negative") == 0);
    pk_context_clear_error(ctx);
    CHECK(pd_float(&d, "neg", 0.0f, PD_POSITIVE, &f) == PK_ERR_PARSE);
    CHECK(strcmp(pk_context_error(ctx), "thing: neg: must be a positive number") == 0);
    pk_context_clear_error(ctx);
    /* pd_set replaces: one entry of the name stays */
    e = num("neg", 3.0);
    REQUIRE(pd_set(&d, &e) == PK_OK);
    CHECK(pd_float(&d, "neg", 0.0f, PD_POSITIVE, &f) == PK_OK && f == 3.0f);
    pd_free(&d);

    /* the unknown-parameter warning: once per parameter not read, in order */
    pd_init(&d, ctx, NULL, NULL, "light 0", true);
    e = num("a", 1);
    REQUIRE(pd_add(&d, &e) == PK_OK);
    e = num("zz", 2);
    REQUIRE(pd_add(&d, &e) == PK_OK);
    e = num("yy", 3);
    REQUIRE(pd_add(&d, &e) == PK_OK);
    static const char *const known[1] = {"a"};
    pd_declare(&d, known, 1);
    warning_log_clear(&w);
    CHECK(pd_report_unused(&d) == PK_OK);
    CHECK(w.count == 2);
    CHECKF(strcmp(w.all, "light 0: zz: unknown parameter ignored\nlight 0: yy: unknown parameter ignored\n") == 0, "%s",
           w.all);
    /* a declared parameter given twice is an error; an unknown one twice is warned about twice */
    e = num("a", 5);
    REQUIRE(pd_add(&d, &e) == PK_OK);
    pd_clear_marks(&d);
    pd_declare(&d, known, 1);
    warning_log_clear(&w);
    CHECK(pd_report_unused(&d) == PK_ERR_PARSE);
    CHECK(strcmp(pk_context_error(ctx), "light 0: a: duplicate key") == 0);
    CHECK(w.count == 2);
    pk_context_clear_error(ctx);
    pd_free(&d);

    /* the cJSON adapter: numbers as read, lists with their non-numbers, the
     * element of a list in a message (the default source names it [k]) */
    cJSON *root = cJSON_Parse("{\"x\": 0.1, \"l\": [1, 2, 1e999], \"m\": [1, \"a\", 3], \"o\": {\"p\": 1},"
                              " \"t\": true, \"n\": null, \"s\": \"str\"}");
    REQUIRE(root);
    pd_init(&d, ctx, NULL, NULL, "json", false);
    REQUIRE(pd_from_cjson(&d, root, "root") == PK_OK);
    CHECK(d.n == 7 && strcmp(d.path, "root") == 0);
    const pd_entry *x = pd_get(&d, "x");
    CHECK(x && x->kind == PD_NUMBER && x->num == 0.1); /* the double, not a float */
    CHECK(pd_get(&d, "o")->kind == PD_OBJECT && pd_get(&d, "t")->kind == PD_BOOL && pd_get(&d, "n")->kind == PD_NULL);
    CHECK(pd_get(&d, "m")->first_other == 1);
    float three[3];
    CHECK(pd_floats(&d, "l", 3, three) == PK_ERR_PARSE);
    CHECKF(strcmp(pk_context_error(ctx), "json: l[2]: numbers must be finite") == 0, "%s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    CHECK(pd_floats(&d, "m", 3, three) == PK_ERR_PARSE);
    CHECK(strcmp(pk_context_error(ctx), "json: m: must be an array of 3 numbers") == 0);
    pk_context_clear_error(ctx);
    pdict sub;
    CHECK(pd_nested(&d, pd_get(&d, "o"), &sub) == PK_ERR_UNSUPPORTED); /* no source: no nested objects */
    pd_free(&sub);
    pk_context_clear_error(ctx);
    warning_log_clear(&w);
    CHECK(pd_report_unused(&d) == PK_OK && w.count == 1); /* "s" was not read */
    CHECK(strcmp(w.all, "json: s: unknown parameter ignored\n") == 0);
    CHECK(pd_string(&d, "s", NULL, &str) == PK_OK && strcmp(str, "str") == 0);
    warning_log_clear(&w);
    CHECK(pd_report_unused(&d) == PK_OK && w.count == 0); /* now it was */
    pd_free(&d);
    cJSON_Delete(root);

    pk_context_destroy(ctx);
    return test_done("test_pdict");
}
