/* private: an openpi policy server as the evaluation's policy, over the
 * WebSocket client (eval_ws.c) */
#ifndef HEARTH_EVAL_WS_H
#define HEARTH_EVAL_WS_H

#include "hearth/sim.h"
#include "hearth/ws.h"

typedef struct eval_ws_policy {
  const char *url;         /* ws://HOST:PORT */
  hearth_ws *c;            /* NULL while not connected */
  double timeout_s;        /* per connect and reply */
  int image_size, thermal, replan;
  double chunk[64][7];     /* the actions of the last reply still to run */
  int nchunk, next;
  char metadata[512];      /* a summary of the server's metadata */
} eval_ws_policy;

/* Connect if not connected, and read the metadata the server sends
 * first (summarised in p->metadata). */
hearth_status eval_ws_ensure(eval_ws_policy *p, hearth_err *err);
/* Send the observation with its prompt, receive a chunk of actions into
 * p->chunk (p->replan of them; p->next = 0). A text reply (openpi's
 * traceback) is the server's error. */
hearth_status eval_ws_query(eval_ws_policy *p, const hearth_sim_obs *ob, const char *prompt, hearth_err *err);
/* Close with the WebSocket close code and forget the connection. */
void eval_ws_drop(eval_ws_policy *p, int code);

#endif
