/* thermal_model.json: a written model reads back the same; the strict
 * reader names the file and the JSON path of what it refuses. */
#include <string.h>

#include "hearth/thermo.h"
#include "test_util.h"

static void expect_error(const char *text, hearth_status status, const char *where) {
  hearth_err err = {0};
  hearth_thermo_model m;
  hearth_status s = hearth_thermo_model_parse(text, strlen(text), "thermal_model.json", &m, &err);
  CHECK_MSG(s == status, "%s: got %s (%s)", text, hearth_status_name(s), err.msg);
  CHECK_MSG(strstr(err.msg, "thermal_model.json") && strstr(err.msg, where), "message: %s",
            err.msg);
}

int main(void) {
  hearth_err err;
  const char *dir = test_tmpdir("thermo_json");
  char path[1200];
  snprintf(path, sizeof path, "%s/thermal_model.json", dir);

  hearth_thermo_model m = {0}, back;
  strcpy(m.category, "cup");
  strcpy(m.offsets, "thermal_offsets.npy");
  CHECK_OK(hearth_thermo_category_net("cup", 80.0, 21.5, &m.net, &err), &err);
  m.net.region[0].T = 61.25;
  CHECK_OK(hearth_thermo_model_write(path, &m, &err), &err);
  CHECK_OK(hearth_thermo_model_read(path, &back, &err), &err);
  CHECK(strcmp(back.category, "cup") == 0 && strcmp(back.offsets, m.offsets) == 0);
  CHECK(back.net.n == m.net.n && back.net.T_air == m.net.T_air);
  for (size_t i = 0; i < m.net.n && i < back.net.n; i++) {
    CHECK(strcmp(back.net.region[i].name, m.net.region[i].name) == 0);
    CHECK(back.net.region[i].C == m.net.region[i].C && back.net.region[i].T == m.net.region[i].T);
    CHECK(back.net.region[i].area == m.net.region[i].area);
    CHECK(back.net.region[i].emissivity == m.net.region[i].emissivity);
    CHECK(back.net.region[i].label == m.net.region[i].label);
    for (size_t j = 0; j < m.net.n; j++) CHECK(back.net.G[i][j] == m.net.G[i][j]);
  }

  const char *head =
      "{\"format\": \"hearth-thermal-model\", \"version\": 1, \"category\": \"cup\", "
      "\"T_air\": 20, \"offsets\": \"\", ";
  char doc[2048];
  snprintf(doc, sizeof doc,
           "%s\"regions\": [{\"name\": \"body\", \"C\": 300, \"T\": 50, \"area\": "
           "0.02, \"h_conv\": 7, \"emissivity\": 0.9, \"label\": 0}], \"conductances\": []}",
           head);
  hearth_thermo_model ok;
  CHECK_OK(hearth_thermo_model_parse(doc, strlen(doc), "thermal_model.json", &ok, &err), &err);
  CHECK(ok.net.n == 1 && ok.net.region[0].C == 300);

  snprintf(doc, sizeof doc,
           "%s\"regions\": [{\"name\": \"body\", \"C\": -3, \"T\": 50, \"area\": "
           "0.02, \"h_conv\": 7, \"emissivity\": 0.9, \"label\": 0}], \"conductances\": []}",
           head);
  expect_error(doc, HEARTH_E_RANGE, "regions[0].C");
  snprintf(doc, sizeof doc,
           "%s\"regions\": [{\"name\": \"body\", \"C\": 3, \"T\": 50, \"area\": "
           "0.02, \"h_conv\": 7, \"emissivity\": 1.5, \"label\": 0}], \"conductances\": []}",
           head);
  expect_error(doc, HEARTH_E_RANGE, "regions[0].emissivity");
  snprintf(doc, sizeof doc,
           "%s\"regions\": [{\"name\": \"body\", \"C\": 3, \"T\": 50, \"area\": "
           "0.02, \"h_conv\": 7, \"emissivity\": 0.5, \"label\": 0, \"mass\": 1}], "
           "\"conductances\": []}",
           head);
  expect_error(doc, HEARTH_E_PARSE, "regions[0].mass");
  snprintf(doc, sizeof doc,
           "%s\"regions\": [{\"name\": \"body\", \"C\": 3, \"T\": 50, \"area\": "
           "0.02, \"h_conv\": 7, \"emissivity\": 0.5, \"label\": 0}], "
           "\"conductances\": [{\"a\": \"body\", \"b\": \"lid\", \"G\": 1}]}",
           head);
  expect_error(doc, HEARTH_E_INCONSISTENT, "conductances[0]");
  expect_error("{\"format\": \"other\"}", HEARTH_E_UNSUPPORTED, "format");
  expect_error("[1]", HEARTH_E_PARSE, "expected a JSON object");
  snprintf(doc, sizeof doc, "%s\"regions\": [], \"conductances\": []}", head);
  expect_error(doc, HEARTH_E_SIZE, "regions");
  return g_test_failures;
}
