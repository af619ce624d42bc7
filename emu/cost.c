/*
** cost.c — counted HITAC-10 operations turned into 1974 seconds.
** Where described: emu/cost.h (the counting rules), emu/hitac10.h (classes and
** instructions), emu/params.c (the times and their sources).
**
** This file contains code to price the counts.  Each class costs a whole number of
** machine states (or, for a trapped multiply or divide, the trap plus the instructions
** of the software routine), and a state lasts state_ns.  So
**     hitac10_seconds = sum over classes of  count x states(class) x state_ns.
** The estimate covers the CPU only; waits for the disk, the drum scanner and the tube
** are added by the stages that use them, from the same parameter table.
*/
#include "emu/cost.h"

static const char *const class_names[COST_NCLASS] = {
  [COST_MEM] = "mem", [COST_ADD] = "add", [COST_LOGIC] = "logic", [COST_SHIFT] = "shift",
  [COST_BRANCH] = "branch", [COST_MUL] = "mul", [COST_DIV] = "div", [COST_IO] = "io",
  [COST_IND] = "ind",
};

const char *cost_class_name(int cls)
{
  return cls >= 0 && cls < COST_NCLASS ? class_names[cls] : "?";
}

void cost_merge(struct cost *into, const struct cost *from)
{
  for (int k = 0; k < COST_NCLASS; k++) {
    into->n[k] += from->n[k];
    COST_X(into, k) += COST_X(from, k);
  }
}

uint64_t cost_total(const struct cost *c)
{
  uint64_t t = 0;
  for (int k = 0; k < COST_NCLASS; k++) t += c->n[k];
  return t;
}

/* States one operation of class cls takes. */
static double class_states(const struct cost_params *p, int cls)
{
  const double *v = p->v;
  int sw = v[CP_MULDIV] != 0;
  switch (cls) {
  case COST_MEM:    return v[CP_MEM_STATES];
  case COST_ADD:    return v[CP_ADD_STATES];
  case COST_LOGIC:  return v[CP_LOGIC_STATES];
  case COST_SHIFT:  return v[CP_SHIFT_STATES] + (v[CP_SHIFT_N] - 1) * v[CP_SHIFT_STEP_STATES];
  case COST_BRANCH: return v[CP_BRANCH_STATES];
  case COST_MUL:    return sw ? v[CP_TRAP_STATES] + v[CP_MUL_SW_INSTR] * v[CP_MEM_STATES]
                              : v[CP_MUL_HW_STATES];
  case COST_DIV:    return sw ? v[CP_TRAP_STATES] + v[CP_DIV_SW_INSTR] * v[CP_MEM_STATES]
                              : v[CP_DIV_HW_STATES];
  case COST_IO:     return v[CP_IO_STATES];
  case COST_IND:    return v[CP_IND_STATES];
  default:          return 0;
  }
}

double cost_class_us(const struct cost_params *p, int cls)
{
  return class_states(p, cls) * p->v[CP_STATE_NS] / 1000.0;
}

void cost_class_states(const struct cost_params *p, double states[COST_NCLASS])
{
  for (int k = 0; k < COST_NCLASS; k++) states[k] = class_states(p, k);
}

double cost_seconds_of(const uint64_t n[COST_NCLASS], const double states[COST_NCLASS],
                       const struct cost_params *p)
{
  double sum = 0;
  for (int k = 0; k < COST_NCLASS; k++) sum += (double)n[k] * states[k];
  return sum * p->v[CP_STATE_NS] * 1e-9;
}

double cost_seconds(const struct cost *c, const struct cost_params *p)
{
  double states[COST_NCLASS];
  cost_class_states(p, states);
  return cost_seconds_of(c->n, states, p);
}

double cost_seconds_exact(const struct cost *c, const struct cost_params *p)
{
  double states = 0;
  for (int k = 0; k < COST_NCLASS; k++)
    states += (double)(c->n[k] + COST_X(c, k)) * class_states(p, k);
  return states * p->v[CP_STATE_NS] * 1e-9;
}

int cost_report(const struct cost *c, const struct cost_params *p, FILE *f)
{
  fprintf(f, "%-8s %16s %10s %14s\n", "class", "count", "us each", "seconds");
  for (int k = 0; k < COST_NCLASS; k++)
    fprintf(f, "%-8s %16llu %10.4f %14.6f\n", class_names[k], (unsigned long long)c->n[k],
            cost_class_us(p, k), (double)c->n[k] * cost_class_us(p, k) * 1e-6);
  fprintf(f, "%-8s %16llu %10s %14.6f  (multiply/divide: %s)\n", "total",
          (unsigned long long)cost_total(c), "", cost_seconds(c, p),
          p->v[CP_MULDIV] != 0 ? "software routines" : "hardware unit");
  return ferror(f) ? T74_EIO : T74_OK;
}
