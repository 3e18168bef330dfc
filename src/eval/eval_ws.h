/* private: an openpi policy server as the evaluation's policy, over the
 * WebSocket client (eval_ws.c) */
#ifndef HEARTH_EVAL_WS_H
#define HEARTH_EVAL_WS_H

#include "hearth/sim.h"
#include "hearth/ws.h"

typedef struct eval_ws_policy {
  const char *url;  /* ws://HOST:PORT */
  hearth_ws *c;     /* NULL while not connected */
  double timeout_s; /* per connect and reply */
  int image_size, thermal, replan;
  double chunk[64][7]; /* the actions of the last reply still to run */
  int nchunk, next;
  char *metadata_json;   /* the server's metadata map as JSON (malloc'd), from
                              the last connection; NULL before one */
  int thermal_decl;      /* what the metadata says about observation/thermal_image:
                              1 read, 0 ignored, -1 nothing said */
  char thermal_why[256]; /* the metadata entry that decided thermal_decl */
} eval_ws_policy;

/* Connect if not connected, and read the metadata the server sends first
 * (into p->metadata_json and p->thermal_decl: "hearth_thermal": false, or an
 * "image_keys" list without "observation/thermal_image", declares the
 * thermal view ignored; "hearth_thermal": true or a list with it, read). */
hearth_status eval_ws_ensure(eval_ws_policy *p, hearth_err *err);
/* Free what p holds and close its connection (code 1000). */
void eval_ws_free(eval_ws_policy *p);
/* Send the observation with its prompt, receive a chunk of actions into
 * p->chunk (p->replan of them; p->next = 0). A text reply (openpi's
 * traceback) is the server's error. */
hearth_status eval_ws_query(eval_ws_policy *p, const hearth_sim_obs *ob, const char *prompt,
                            hearth_err *err);
/* Close with the WebSocket close code and forget the connection. */
void eval_ws_drop(eval_ws_policy *p, int code);

#endif
