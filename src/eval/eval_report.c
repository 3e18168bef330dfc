/* Evaluation results as the paper's table (text, Markdown) and as JSON
 * with every episode. */
#include <jansson.h>
#include <math.h>

#include "hearth/eval.h"

double hearth_eval_rates(const hearth_eval_results *r, double per_instr[HEARTH_SIM_TASK_END][2],
                         double per_task[HEARTH_SIM_TASK_END]) {
  int n[HEARTH_SIM_TASK_END][2] = {{0}}, k[HEARTH_SIM_TASK_END][2] = {{0}}, tot = 0, ok = 0;
  for (size_t i = 0; i < r->n; i++) {
    const hearth_eval_episode *e = &r->eps[i];
    n[e->task][e->instruction]++;
    k[e->task][e->instruction] += e->success;
    tot++, ok += e->success;
  }
  for (int t = 0; t < HEARTH_SIM_TASK_END; t++) {
    int nt = n[t][0] + n[t][1];
    if (per_task) per_task[t] = nt ? (double)(k[t][0] + k[t][1]) / nt : NAN;
    for (int i = 0; i < 2; i++)
      if (per_instr) per_instr[t][i] = n[t][i] ? (double)k[t][i] / n[t][i] : NAN;
  }
  return tot ? (double)ok / tot : NAN;
}

static const char *pct(double f, char *buf) {
  if (isnan(f)) return "-";
  hearth_format_fixed(buf, 32, 100.0 * f, 1);
  return buf;
}

static const char *thermal_label(const hearth_eval_results *r) {
  return r->thermal < 0 ? "-" : !r->thermal ? "w/o" : r->thermal_used < 0 ? "w/?" : "w/";
}

/* what the run was: sizes, replanning, lighting, renderer, and for a
 * server what it said about the thermal view */
static void setup_lines(const hearth_eval_results *r, hearth_strbuf *b) {
  hearth_strbuf_printf(b, "setup: render %d px", r->render_size);
  if (r->thermal >= 0)
    hearth_strbuf_printf(b, ", policy images %d px, replan every %d steps after %d no-op steps",
                         r->image_size, r->replan_steps, r->wait_steps);
  hearth_strbuf_printf(b, ", shadows %s, renderer %s\n", r->shadows ? "on" : "off",
                       r->renderer[0] ? r->renderer : "-");
  if (r->thermal >= 0)
    hearth_strbuf_printf(b, "thermal image: %s\n",
                         !r->thermal ? "not sent (--no-thermal)"
                         : r->thermal_used > 0
                             ? "sent; the server declares it reads it"
                             : "sent; the server does not declare whether it reads it (unknown)");
  if (r->metadata_json) hearth_strbuf_printf(b, "server metadata: %s\n", r->metadata_json);
  if (r->warning[0]) hearth_strbuf_printf(b, "warning: %s\n", r->warning);
}

static void counts(const hearth_eval_results *r, int *ok, int *tot) {
  *ok = *tot = 0;
  for (size_t i = 0; i < r->n; i++) *ok += r->eps[i].success, (*tot)++;
}

char *hearth_eval_format_text(const hearth_eval_results *r) {
  double pi[HEARTH_SIM_TASK_END][2], pt[HEARTH_SIM_TASK_END];
  double all = hearth_eval_rates(r, pi, pt);
  hearth_strbuf b = {0};
  for (size_t i = 0; i < r->n; i++)
    if (!r->eps[i].success)
      hearth_strbuf_printf(&b, "failed: %s instr %d episode %d (layout %llu): %s\n",
                           hearth_sim_task_name(r->eps[i].task), r->eps[i].instruction + 1,
                           r->eps[i].episode, (unsigned long long)r->eps[i].layout,
                           r->eps[i].reason);
  hearth_strbuf_printf(&b, "policy %s\n", r->policy);
  setup_lines(r, &b);
  hearth_strbuf_printf(&b, "%-6s %-8s %9s %9s %9s\n", "Task", "Thermal", "Instr. 1", "Instr. 2",
                       "Average");
  for (int t = 1; t < HEARTH_SIM_TASK_END; t++) {
    if (isnan(pt[t])) continue;
    char a[32], c[32], d[32];
    hearth_strbuf_printf(&b, "%-6s %-8s %9s %9s %9s\n", hearth_sim_task_name((hearth_sim_task)t),
                         thermal_label(r), pct(pi[t][0], a), pct(pi[t][1], c), pct(pt[t], d));
  }
  int ok, tot;
  counts(r, &ok, &tot);
  char a[32];
  size_t perr = hearth_eval_policy_errors(r);
  if (perr)
    hearth_strbuf_printf(
        &b, "policy errors: %zu of %d episodes failed because of the policy, not the task\n", perr,
        tot);
  hearth_strbuf_printf(&b, "overall %s (%d/%d)\n", pct(all, a), ok, tot);
  return hearth_strbuf_take(&b);
}

char *hearth_eval_format_markdown(const hearth_eval_results *r) {
  double pi[HEARTH_SIM_TASK_END][2], pt[HEARTH_SIM_TASK_END];
  double all = hearth_eval_rates(r, pi, pt);
  hearth_strbuf b = {0};
  hearth_strbuf_printf(&b, "Task success rates (%%), policy `%s`\n\n", r->policy);
  hearth_strbuf_printf(
      &b, "| Task | Thermal | Instr. 1 | Instr. 2 | Average |\n|---|---|---:|---:|---:|\n");
  for (int t = 1; t < HEARTH_SIM_TASK_END; t++) {
    if (isnan(pt[t])) continue;
    char a[32], c[32], d[32];
    hearth_strbuf_printf(&b, "| %s | %s | %s | %s | %s |\n",
                         hearth_sim_task_name((hearth_sim_task)t), thermal_label(r),
                         pct(pi[t][0], a), pct(pi[t][1], c), pct(pt[t], d));
  }
  int ok, tot;
  counts(r, &ok, &tot);
  char a[32];
  hearth_strbuf_printf(&b, "| **Overall** | %s | | | **%s** (%d/%d) |\n", thermal_label(r),
                       pct(all, a), ok, tot);
  return hearth_strbuf_take(&b);
}

static json_t *jnum(double v) {
  if (isnan(v)) return json_null();
  return json_real(round(v * 1e4) / 1e4);
}

char *hearth_eval_format_json(const hearth_eval_results *r) {
  double pi[HEARTH_SIM_TASK_END][2], pt[HEARTH_SIM_TASK_END];
  double all = hearth_eval_rates(r, pi, pt);
  json_t *root = json_object();
  json_object_set_new(root, "policy", json_string(r->policy));
  json_object_set_new(root, "thermal", r->thermal < 0 ? json_null() : json_boolean(r->thermal));
  json_object_set_new(root, "thermal_used",
                      r->thermal < 0        ? json_null()
                      : r->thermal_used < 0 ? json_string("unknown")
                                            : json_boolean(r->thermal_used));
  json_t *meta = NULL;
  if (r->metadata_json) {
    json_error_t je;
    meta = json_loads(r->metadata_json, 0, &je);
  }
  json_object_set_new(root, "server_metadata", meta ? meta : json_null());
  json_object_set_new(root, "render_size", json_integer(r->render_size));
  json_object_set_new(root, "image_size", json_integer(r->image_size));
  json_object_set_new(root, "replan_steps", json_integer(r->replan_steps));
  json_object_set_new(root, "wait_steps", json_integer(r->wait_steps));
  json_object_set_new(root, "shadows", json_boolean(r->shadows));
  json_object_set_new(root, "renderer", json_string(r->renderer));
  json_object_set_new(root, "warning", r->warning[0] ? json_string(r->warning) : json_null());
  json_object_set_new(root, "overall_success", jnum(all));
  int ok, tot;
  counts(r, &ok, &tot);
  size_t perr = hearth_eval_policy_errors(r);
  json_object_set_new(root, "successes", json_integer(ok));
  json_object_set_new(root, "episodes_total", json_integer(tot));
  json_object_set_new(root, "policy_errors", json_integer((json_int_t)perr));
  json_object_set_new(root, "task_failures", json_integer(tot - ok - (json_int_t)perr));
  json_t *tasks = json_object();
  for (int t = 1; t < HEARTH_SIM_TASK_END; t++) {
    if (isnan(pt[t])) continue;
    json_t *jt = json_object();
    json_object_set_new(jt, "instruction_1", jnum(pi[t][0]));
    json_object_set_new(jt, "instruction_2", jnum(pi[t][1]));
    json_object_set_new(jt, "average", jnum(pt[t]));
    json_object_set_new(jt, "time_limit", json_integer(hearth_eval_time_limit((hearth_sim_task)t)));
    json_object_set_new(tasks, hearth_sim_task_name((hearth_sim_task)t), jt);
  }
  json_object_set_new(root, "tasks", tasks);
  json_t *eps = json_array();
  for (size_t i = 0; i < r->n; i++) {
    const hearth_eval_episode *e = &r->eps[i];
    json_t *je = json_object();
    json_object_set_new(je, "task", json_string(hearth_sim_task_name(e->task)));
    json_object_set_new(je, "instruction", json_integer(e->instruction + 1));
    json_object_set_new(je, "episode", json_integer(e->episode));
    json_object_set_new(je, "seed", json_integer((json_int_t)e->seed));
    json_object_set_new(je, "layout", json_integer((json_int_t)e->layout));
    json_object_set_new(je, "success", json_boolean(e->success));
    json_object_set_new(je, "steps", json_integer(e->steps));
    json_object_set_new(je, "policy_error", json_boolean(e->error));
    json_object_set_new(je, "reason", json_string(e->reason));
    if (e->state_diff >= 0)
      json_object_set_new(je, "replay_max_state_diff", json_real(e->state_diff));
    json_array_append_new(eps, je);
  }
  json_object_set_new(root, "episodes", eps);
  json_object_set_new(root, "seconds", json_real(round(r->seconds * 100) / 100));
  char *s = json_dumps(root, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
  json_decref(root);
  return s;
}
