/* Interoperability client on a second DDS implementation (Eclipse Cyclone DDS, C API) for the
 * drivegate DDS interface (README.md "DDS interface", idl/drivegate.idl). It uses nothing of
 * drivegate but the IDL, compiled by Cyclone's idlc, and talks to a running gateway:
 *   1. waits for an axis_state sample of the axis and prints it;
 *   2. enable, a small relative move, disable on axis_command, each until command_reply says
 *      "completed";
 *   3. one parameter read on param_request, until param_reply says ok.
 * Every result is printed as one line; the exit status is 0 only if all of them succeeded
 * (1: a step failed, 2: bad arguments or DDS setup error, 3: a step timed out).
 *
 * QoS is exactly the gateway's (idl/dds_node.cpp), and every reader and writer is restricted to
 * the XCDR1 data representation: the types are @final and the gateway (Fast DDS 2.9, fastddsgen
 * 2.3) only reads and writes plain XCDR1, so a writer must never pick XCDR2.
 *
 * Networking comes from CYCLONEDDS_URI (the interop test keeps it on loopback). */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <inttypes.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "dds/dds.h"
#include "drivegate.h"

enum { EXIT_STEP_FAILED = 1, EXIT_SETUP = 2, EXIT_TIMEOUT = 3 };
enum { MAX_TAKE = 16 };

struct options {
  uint32_t domain;
  const char *ns;
  const char *gateway;
  const char *axis;
  uint16_t param_index;
  uint8_t param_subindex;
  double timeout_s;
};

struct client {
  struct options opt;
  char name[96];
  uint64_t next_command_id;
  uint64_t next_param_id;
  dds_entity_t participant;
  dds_entity_t state_reader;
  dds_entity_t command_writer;
  dds_entity_t command_reply_reader;
  dds_entity_t param_writer;
  dds_entity_t param_reply_reader;
};

/* Outcome of one step. */
enum outcome { OK, FAILED, TIMED_OUT };

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void fail_setup(const char *what, dds_return_t rc) {
  fprintf(stderr, "cyclone_client: %s: %s\n", what, dds_strretcode(rc));
  exit(EXIT_SETUP);
}

static dds_entity_t check_entity(dds_entity_t e, const char *what) {
  if (e < 0) fail_setup(what, e);
  return e;
}

static void usage(const char *msg) {
  if (msg != NULL) fprintf(stderr, "cyclone_client: %s\n", msg);
  fprintf(stderr,
          "usage: cyclone_client --domain N --namespace NS --gateway NAME --axis AXIS\n"
          "                      [--param INDEX:SUB] [--timeout SECONDS]\n"
          "  --param    object to read, hexadecimal as in CiA 301 (default 6064:0), read as 4 bytes signed\n"
          "  --timeout  how long each step may take: discovery, each reply (default 10)\n");
  exit(EXIT_SETUP);
}

static bool parse_ulong(const char *s, int base, unsigned long max, unsigned long *out) {
  char *end = NULL;
  errno = 0;
  const unsigned long v = strtoul(s, &end, base);
  if (errno != 0 || end == s || *end != '\0' || v > max || s[0] == '-') return false;
  *out = v;
  return true;
}

static struct options parse_options(int argc, char **argv) {
  struct options o = {0, NULL, NULL, NULL, 0x6064, 0, 10.0};
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    if (i + 1 >= argc) usage("every option takes a value");
    const char *v = argv[++i];
    unsigned long n = 0;
    if (strcmp(a, "--domain") == 0) {
      if (!parse_ulong(v, 10, 232, &n)) usage("--domain must be 0..232");
      o.domain = (uint32_t)n;
    } else if (strcmp(a, "--namespace") == 0) {
      o.ns = v;
    } else if (strcmp(a, "--gateway") == 0) {
      o.gateway = v;
    } else if (strcmp(a, "--axis") == 0) {
      o.axis = v;
    } else if (strcmp(a, "--param") == 0) {
      char buf[32];
      if (strlen(v) >= sizeof buf) usage("--param must be INDEX:SUB, e.g. 6064:0");
      strcpy(buf, v);
      char *colon = strchr(buf, ':');
      if (colon == NULL) usage("--param must be INDEX:SUB, e.g. 6064:0");
      *colon = '\0';
      unsigned long sub = 0;
      if (!parse_ulong(buf, 16, 0xFFFF, &n) || !parse_ulong(colon + 1, 16, 0xFF, &sub))
        usage("--param must be INDEX:SUB in hexadecimal, e.g. 6064:0");
      o.param_index = (uint16_t)n;
      o.param_subindex = (uint8_t)sub;
    } else if (strcmp(a, "--timeout") == 0) {
      char *end = NULL;
      o.timeout_s = strtod(v, &end);
      if (end == v || *end != '\0' || !(o.timeout_s > 0.0) || o.timeout_s > 3600.0)
        usage("--timeout must be a number of seconds, 0 < t <= 3600");
    } else {
      usage("unknown option");
    }
  }
  if (o.ns == NULL || o.gateway == NULL || o.axis == NULL)
    usage("--domain, --namespace, --gateway and --axis are required");
  return o;
}

/* The gateway's QoS for each topic (idl/dds_node.cpp), always with XCDR1. */
enum topic_qos { QOS_STATE, QOS_REQUEST, QOS_REPLY };

static dds_qos_t *make_qos(enum topic_qos kind) {
  dds_qos_t *q = dds_create_qos();
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(q, 1, &xcdr1);
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  if (kind == QOS_STATE) {
    dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
  } else {
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
  }
  return q;
}

static dds_entity_t make_topic(struct client *c, const dds_topic_descriptor_t *desc, const char *suffix) {
  char name[256];
  snprintf(name, sizeof name, "%s/%s", c->opt.ns, suffix);
  return check_entity(dds_create_topic(c->participant, desc, name, NULL, NULL), name);
}

static dds_entity_t make_reader(struct client *c, const dds_topic_descriptor_t *desc, const char *suffix,
                                enum topic_qos kind) {
  dds_qos_t *q = make_qos(kind);
  const dds_entity_t r = dds_create_reader(c->participant, make_topic(c, desc, suffix), q, NULL);
  dds_delete_qos(q);
  return check_entity(r, suffix);
}

static dds_entity_t make_writer(struct client *c, const dds_topic_descriptor_t *desc, const char *suffix) {
  dds_qos_t *q = make_qos(QOS_REQUEST);
  const dds_entity_t w = dds_create_writer(c->participant, make_topic(c, desc, suffix), q, NULL);
  dds_delete_qos(q);
  check_entity(w, suffix);
  dds_return_t rc = dds_set_status_mask(w, DDS_PUBLICATION_MATCHED_STATUS);
  if (rc != DDS_RETCODE_OK) fail_setup("dds_set_status_mask", rc);
  return w;
}

/* Waits on `n` entities until `done(c, arg)` holds or `deadline` (now_s() time) passes. */
typedef bool (*predicate)(struct client *c, void *arg);

static enum outcome wait_until(struct client *c, const dds_entity_t *conds, size_t n, double deadline, predicate done,
                               void *arg) {
  const dds_entity_t ws = check_entity(dds_create_waitset(c->participant), "waitset");
  for (size_t i = 0; i < n; i++) {
    const dds_return_t rc = dds_waitset_attach(ws, conds[i], (dds_attach_t)i);
    if (rc != DDS_RETCODE_OK) fail_setup("dds_waitset_attach", rc);
  }
  enum outcome result = TIMED_OUT;
  for (;;) {
    if (done(c, arg)) {
      result = OK;
      break;
    }
    const double left = deadline - now_s();
    if (left <= 0.0) break;
    const dds_return_t rc = dds_waitset_wait(ws, NULL, 0, (dds_duration_t)(left * 1e9) + 1);
    if (rc < 0) fail_setup("dds_waitset_wait", rc);
  }
  dds_delete(ws);
  return result;
}

/* --- discovery ------------------------------------------------------------------------------ */

static bool writers_and_readers_matched(struct client *c, void *arg) {
  (void)arg;
  const dds_entity_t writers[] = {c->command_writer, c->param_writer};
  const dds_entity_t readers[] = {c->command_reply_reader, c->param_reply_reader};
  bool all = true;
  for (size_t i = 0; i < 2; i++) {
    dds_publication_matched_status_t p;
    dds_subscription_matched_status_t s;
    if (dds_get_publication_matched_status(writers[i], &p) != DDS_RETCODE_OK || p.current_count == 0) all = false;
    if (dds_get_subscription_matched_status(readers[i], &s) != DDS_RETCODE_OK || s.current_count == 0) all = false;
  }
  return all;
}

/* --- axis_state ----------------------------------------------------------------------------- */

struct state_wait {
  bool have;
  drivegate_msg_AxisState copy;  /* strings point into `text` */
  char text[5][96];
};

static void keep(char *dst, const char *src) {
  snprintf(dst, 96, "%s", src != NULL ? src : "");
}

static bool take_state(struct client *c, void *arg) {
  struct state_wait *w = arg;
  void *samples[MAX_TAKE] = {NULL};
  dds_sample_info_t infos[MAX_TAKE];
  const dds_return_t n = dds_take(c->state_reader, samples, infos, MAX_TAKE, MAX_TAKE);
  if (n < 0) fail_setup("dds_take axis_state", n);
  for (dds_return_t i = 0; i < n; i++) {
    const drivegate_msg_AxisState *s = samples[i];
    if (!infos[i].valid_data || strcmp(s->gateway, c->opt.gateway) != 0 || strcmp(s->axis, c->opt.axis) != 0)
      continue;
    w->have = true;
    w->copy = *s;
    keep(w->text[0], s->gateway);
    keep(w->text[1], s->axis);
    keep(w->text[2], s->state);
    keep(w->text[3], s->mode);
    keep(w->text[4], s->unit);
    w->copy.gateway = w->text[0];
    w->copy.axis = w->text[1];
    w->copy.state = w->text[2];
    w->copy.mode = w->text[3];
    w->copy.unit = w->text[4];
    w->copy.link = NULL;
    w->copy.fault_text = NULL;
  }
  if (n > 0) dds_return_loan(c->state_reader, samples, n);
  return w->have;
}

/* fresh: ignore what the reader holds already and wait for the next sample. */
static enum outcome read_state(struct client *c, const char *label, bool fresh) {
  struct state_wait w;
  memset(&w, 0, sizeof w);
  if (fresh) {
    (void)take_state(c, &w);
    memset(&w, 0, sizeof w);
  }
  const dds_entity_t rc = check_entity(dds_create_readcondition(c->state_reader, DDS_ANY_STATE), "readcondition");
  const enum outcome r = wait_until(c, &rc, 1, now_s() + c->opt.timeout_s, take_state, &w);
  dds_delete(rc);
  if (r != OK) {
    printf("%s: TIMEOUT: no axis_state sample of gateway %s axis %s within %.1f s\n", label, c->opt.gateway,
           c->opt.axis, c->opt.timeout_s);
    return r;
  }
  const drivegate_msg_AxisState *s = &w.copy;
  printf("%s: gateway=%s axis=%s state=%s mode=%s position=%.4f %s velocity=%.4f fault_code=0x%" PRIx32
         " statusword=0x%04" PRIx16 " seq=%" PRIu64 "\n",
         label, s->gateway, s->axis, s->state, s->mode, s->position, s->unit, s->velocity, s->fault_code,
         s->statusword, s->seq);
  return OK;
}

/* --- requests and replies ------------------------------------------------------------------ */

/* Why an idempotent request is sent again when nothing at all came back within RESEND_S:
 * a Cyclone volatile reader treats everything up to the last sequence number of the first
 * heartbeat it processes from a writer as history and drops it. The gateway (Fast DDS) matches
 * our reply readers long before we have discovered its reply writers, sends its one initial
 * heartbeat while we still ignore it, and the next heartbeat goes out only together with the
 * first reply, announcing the reply before the reply itself arrives: Cyclone then drops the first
 * reply(ies) of each reply writer (deterministically when the writer holds replies to earlier
 * clients). From the first reply on, the reader is in sync and nothing more is lost. So enable,
 * disable and parameter reads (which do no harm twice) are resent with a new id; a reply to any
 * id of the step counts. The relative move is never resent: it is not idempotent, and it comes
 * after enable, whose reply has brought the command_reply reader in sync. */
#define RESEND_S 1.0

struct reply_wait {
  uint64_t first_id, last_id;  /* the ids this step has sent */
  uint64_t id;                 /* the id that replied */
  bool any;                    /* some reply (also "accepted") arrived */
  bool final;
  bool completed;
  char status[32];
  char reason[256];
};

static bool take_command_reply(struct client *c, void *arg) {
  struct reply_wait *w = arg;
  void *samples[MAX_TAKE] = {NULL};
  dds_sample_info_t infos[MAX_TAKE];
  const dds_return_t n = dds_take(c->command_reply_reader, samples, infos, MAX_TAKE, MAX_TAKE);
  if (n < 0) fail_setup("dds_take command_reply", n);
  for (dds_return_t i = 0; i < n && !w->final; i++) {
    const drivegate_msg_CommandReply *r = samples[i];
    if (!infos[i].valid_data || strcmp(r->client, c->name) != 0 || r->id < w->first_id || r->id > w->last_id)
      continue;
    w->any = true;
    w->id = r->id;
    snprintf(w->status, sizeof w->status, "%s", r->status);
    snprintf(w->reason, sizeof w->reason, "%s", r->reason);
    if (strcmp(r->status, "accepted") == 0) continue; /* the final reply follows */
    w->final = true;
    w->completed = strcmp(r->status, "completed") == 0;
  }
  if (n > 0) dds_return_loan(c->command_reply_reader, samples, n);
  return w->final;
}

static enum outcome command(struct client *c, const char *kind, bool relative, double position, bool resend) {
  drivegate_msg_AxisCommand cmd;
  memset(&cmd, 0, sizeof cmd);
  cmd.gateway = (char *)c->opt.gateway;
  cmd.axis = (char *)c->opt.axis;
  cmd.client = c->name;
  cmd.kind = (char *)kind;
  cmd.mode = "";
  cmd.position = position;
  cmd.relative = relative; /* velocity, acceleration, deceleration 0: the axis defaults */

  struct reply_wait w;
  memset(&w, 0, sizeof w);
  w.first_id = c->next_command_id;
  const dds_entity_t cond =
      check_entity(dds_create_readcondition(c->command_reply_reader, DDS_ANY_STATE), "readcondition");
  const double t0 = now_s();
  const double deadline = t0 + c->opt.timeout_s;
  enum outcome r = TIMED_OUT;
  for (;;) {
    cmd.id = w.last_id = c->next_command_id++;
    const dds_return_t rc = dds_write(c->command_writer, &cmd);
    if (rc != DDS_RETCODE_OK) fail_setup("dds_write axis_command", rc);
    const double resend_at = now_s() + RESEND_S;
    r = wait_until(c, &cond, 1, resend && resend_at < deadline ? resend_at : deadline, take_command_reply, &w);
    if (r == OK || now_s() >= deadline) break;
    if (w.any) { /* accepted: wait for the final reply */
      r = wait_until(c, &cond, 1, deadline, take_command_reply, &w);
      break;
    }
    printf("command %s id=%" PRIu64 ": no reply within %.1f s, sending it again\n", kind, cmd.id, RESEND_S);
  }
  dds_delete(cond);
  const double ms = (now_s() - t0) * 1e3;
  if (r != OK) {
    printf("command %s id=%" PRIu64 ": TIMEOUT after %.0f ms (last reply: %s)\n", kind, w.last_id, ms,
           w.any ? w.status : "none");
    return r;
  }
  printf("command %s id=%" PRIu64 ": %s%s%s (%.0f ms)\n", kind, w.id, w.status, w.reason[0] != '\0' ? ": " : "",
         w.reason, ms);
  return w.completed ? OK : FAILED;
}

struct param_wait {
  uint64_t first_id, last_id;
  uint64_t id;
  bool have;
  bool ok;
  int64_t value;
  uint32_t error_code;
  char error[256];
  char type_error[96];
};

static bool take_param_reply(struct client *c, void *arg) {
  struct param_wait *w = arg;
  void *samples[MAX_TAKE] = {NULL};
  dds_sample_info_t infos[MAX_TAKE];
  const dds_return_t n = dds_take(c->param_reply_reader, samples, infos, MAX_TAKE, MAX_TAKE);
  if (n < 0) fail_setup("dds_take param_reply", n);
  for (dds_return_t i = 0; i < n && !w->have; i++) {
    const drivegate_msg_ParameterReply *r = samples[i];
    if (!infos[i].valid_data || strcmp(r->client, c->name) != 0 || r->id < w->first_id || r->id > w->last_id)
      continue;
    w->have = true;
    w->id = r->id;
    /* The gateway types 6064h as INTEGER32 (CiA 402): four little-endian bytes. */
    w->ok = r->ok && strcmp(r->type, "i32") == 0 && r->data._length == 4;
    if (r->ok && !w->ok)
      snprintf(w->type_error, sizeof w->type_error, "type '%s' with %" PRIu32 " bytes, expected i32 with 4", r->type,
               r->data._length);
    if (w->ok) {
      uint32_t raw = 0;
      for (int b = 3; b >= 0; b--) raw = (raw << 8) | r->data._buffer[b];
      w->value = (int32_t)raw;
    }
    w->error_code = r->error_code;
    snprintf(w->error, sizeof w->error, "%s", r->error);
  }
  if (n > 0) dds_return_loan(c->param_reply_reader, samples, n);
  return w->have;
}

static enum outcome param_read(struct client *c) {
  drivegate_msg_ParameterRequest req;
  memset(&req, 0, sizeof req);
  req.gateway = (char *)c->opt.gateway;
  req.axis = (char *)c->opt.axis;
  req.client = c->name;
  req.write = false;
  req.index = c->opt.param_index;
  req.subindex = c->opt.param_subindex;
  req.name = "";
  req.type = ""; /* the gateway's type for the object */
  req.value = "";

  struct param_wait w;
  memset(&w, 0, sizeof w);
  w.first_id = c->next_param_id;
  const dds_entity_t cond =
      check_entity(dds_create_readcondition(c->param_reply_reader, DDS_ANY_STATE), "readcondition");
  const double t0 = now_s();
  const double deadline = t0 + c->opt.timeout_s;
  enum outcome r = TIMED_OUT;
  for (;;) {
    req.id = w.last_id = c->next_param_id++;
    const dds_return_t rc = dds_write(c->param_writer, &req);
    if (rc != DDS_RETCODE_OK) fail_setup("dds_write param_request", rc);
    const double resend_at = now_s() + RESEND_S;
    r = wait_until(c, &cond, 1, resend_at < deadline ? resend_at : deadline, take_param_reply, &w);
    if (r == OK || now_s() >= deadline) break;
    printf("param read %04" PRIX16 ":%" PRIX8 " id=%" PRIu64 ": no reply within %.1f s, sending it again\n",
           req.index, req.subindex, req.id, RESEND_S);
  }
  dds_delete(cond);
  const double ms = (now_s() - t0) * 1e3;
  if (r != OK) {
    printf("param read %04" PRIX16 ":%" PRIX8 " id=%" PRIu64 ": TIMEOUT after %.0f ms\n", req.index, req.subindex,
           w.last_id, ms);
    return r;
  }
  if (!w.ok) {
    printf("param read %04" PRIX16 ":%" PRIX8 " id=%" PRIu64 ": FAILED error_code=0x%08" PRIX32 " %s%s (%.0f ms)\n",
           req.index, req.subindex, w.id, w.error_code, w.error, w.type_error, ms);
    return FAILED;
  }
  printf("param read %04" PRIX16 ":%" PRIX8 " id=%" PRIu64 ": ok value=%" PRId64 " (%.0f ms)\n", req.index,
         req.subindex, w.id, w.value, ms);
  return OK;
}

/* --- main ----------------------------------------------------------------------------------- */

static int exit_code(enum outcome o) {
  return o == OK ? 0 : o == TIMED_OUT ? EXIT_TIMEOUT : EXIT_STEP_FAILED;
}

static enum outcome worst(enum outcome a, enum outcome b) {
  return a == TIMED_OUT || b == TIMED_OUT ? TIMED_OUT : a == FAILED || b == FAILED ? FAILED : OK;
}

int main(int argc, char **argv) {
  struct client c;
  memset(&c, 0, sizeof c);
  c.opt = parse_options(argc, argv);
  char host[64] = "host";
  gethostname(host, sizeof host - 1);
  snprintf(c.name, sizeof c.name, "cyclone-%s-%ld", host, (long)getpid());
  c.next_command_id = 1;
  c.next_param_id = 1;
  setvbuf(stdout, NULL, _IOLBF, 0);

  const double t_start = now_s();
  c.participant = check_entity(dds_create_participant(c.opt.domain, NULL, NULL), "dds_create_participant");
  /* Readers first, so that the gateway's reply writers can match them while our writers are being
   * discovered. */
  c.state_reader = make_reader(&c, &drivegate_msg_AxisState_desc, "axis_state", QOS_STATE);
  c.command_reply_reader = make_reader(&c, &drivegate_msg_CommandReply_desc, "command_reply", QOS_REPLY);
  c.param_reply_reader = make_reader(&c, &drivegate_msg_ParameterReply_desc, "param_reply", QOS_REPLY);
  c.command_writer = make_writer(&c, &drivegate_msg_AxisCommand_desc, "axis_command");
  c.param_writer = make_writer(&c, &drivegate_msg_ParameterRequest_desc, "param_request");

  printf("client %s on domain %" PRIu32 ", namespace %s, gateway %s, axis %s\n", c.name, c.opt.domain, c.opt.ns,
         c.opt.gateway, c.opt.axis);

  enum outcome result = read_state(&c, "axis_state", false);
  if (result == OK) {
    /* Before the first write the command and parameter writers must have matched the gateway's
     * readers (a volatile writer drops what it writes before that), and the reply readers the
     * gateway's writers. */
    const dds_entity_t ents[] = {c.command_writer, c.param_writer, c.command_reply_reader, c.param_reply_reader};
    for (size_t i = 2; i < 4; i++) {
      const dds_return_t rc = dds_set_status_mask(ents[i], DDS_SUBSCRIPTION_MATCHED_STATUS);
      if (rc != DDS_RETCODE_OK) fail_setup("dds_set_status_mask", rc);
    }
    const double t0 = now_s();
    result = wait_until(&c, ents, 4, t0 + c.opt.timeout_s, writers_and_readers_matched, NULL);
    if (result == OK)
      printf("matched: axis_command, param_request, command_reply, param_reply (%.0f ms)\n", (now_s() - t0) * 1e3);
    else
      printf("matched: TIMEOUT: the gateway's axis_command/param_request readers or command_reply/param_reply "
             "writers were not matched within %.1f s\n", c.opt.timeout_s);
  }
  if (result == OK) {
    result = command(&c, "enable", false, 0.0, true);
    if (result == OK) {
      enum outcome moved = command(&c, "move", true, 1.0, false);
      if (moved == OK) moved = read_state(&c, "axis_state after move", true);
      /* Disable even when the move failed: the axis must not be left enabled. */
      result = worst(moved, command(&c, "disable", false, 0.0, true));
    }
  }
  if (result == OK) result = param_read(&c);

  dds_delete(c.participant);
  if (result == OK)
    printf("interop: all steps succeeded (%.2f s)\n", now_s() - t_start);
  else
    printf("interop: FAILED (%s)\n", result == TIMED_OUT ? "timeout" : "a step failed");
  return exit_code(result);
}
