// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: one reader for the styles' arguments, so that every
   style checks arity, numbers, yes/no, choices and axes the same way and
   every message starts with the style's full name ("Fix fluid/drag: ...").
------------------------------------------------------------------------- */

#ifndef LMP_SEDIMENT_ARGS_H
#define LMP_SEDIMENT_ARGS_H

#include "atom.h"
#include "compute.h"
#include "error.h"
#include "fix.h"
#include "lammps.h"
#include "modify.h"
#include "sediment_lammps_api.h"
#include "update.h"
#include "utils.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

namespace LAMMPS_NS {

// 0, 1, 2 for "x", "y", "z"; -1 for anything else (the caller names the keyword in its error).
inline int sediment_axis(const char *name)
{
  for (int d = 0; d < 3; ++d)
    if (strcmp(name, d == 0 ? "x" : d == 1 ? "y" : "z") == 0) return d;
  return -1;
}

class StyleArgs {
 public:
  // `style` is the style's full name as the user wrote it ("Fix fluid/drag", "Pair lubricate/fluid");
  // keywords start at arg[first]; errors name the style's source at `file`, `line` (FLERR).
  StyleArgs(LAMMPS *lmp, const char *file, int line, std::string style, int narg, char **arg, int first) :
      lmp(lmp), file(file), line(line), style(std::move(style)), narg(narg), arg(arg), iarg(first)
  {
  }

  bool more() const { return iarg < narg; }
  bool is(const char *name) const { return strcmp(arg[iarg], name) == 0; }
  // Whether the keyword has at least n values after it.
  bool has(int n) const { return iarg + n < narg; }
  // The k-th value after the current keyword (k = 1 is the first).
  const char *text(int k) const { return arg[iarg + k]; }
  // How many words follow the keyword, up to the first that is not a number.
  int numbers_after() const
  {
    int n = 0;
    while (iarg + 1 + n < narg && utils::is_double(arg[iarg + 1 + n])) ++n;
    return n;
  }
  // Moves past the keyword and its n values.
  void next(int n) { iarg += 1 + n; }

  // Stops unless the keyword has n values; `what` says what they are ("a value", "an axis and a count").
  void need(int n, const char *what) const
  {
    if (!has(n)) fail("keyword '{}' needs {}", arg[iarg], what);
  }

  double number(int k) const
  {
    const double value = utils::numeric(file, line, arg[iarg + k], false, lmp);
    // utils::numeric turns 1e400 into inf: finiteness is checked here, once for every style.
    if (!std::isfinite(value)) fail("{} must be finite, not '{}'", arg[iarg], arg[iarg + k]);
    return value;
  }
  // A finite number > 0, or "<Style>: <what> must be finite and > 0<hint>".
  double positive(int k, const std::string &what, const char *hint = "") const
  {
    const double value = utils::numeric(file, line, arg[iarg + k], false, lmp);
    if (!(value > 0.0) || !std::isfinite(value)) fail("{} must be finite and > 0{}", what, hint);
    return value;
  }
  // A whole number from 1 to `most`, read as a 64-bit integer so that a too large one is named, not wrapped.
  int count(int k, bigint most) const
  {
    const bigint value = utils::bnumeric(file, line, arg[iarg + k], false, lmp);
    if (value < 1 || value > most) fail("{} count {} must be from 1 to {}", arg[iarg], arg[iarg + k], most);
    return static_cast<int>(value);
  }
  bool yes_no(int k) const
  {
    const char *word = arg[iarg + k];
    if (strcmp(word, "yes") == 0) return true;
    if (strcmp(word, "no") != 0) fail("{} must be yes or no, not '{}'", arg[iarg], word);
    return false;
  }
  // Index of the k-th value in `names`, or an error listing them.
  int choice(int k, std::initializer_list<const char *> names) const
  {
    int index = 0;
    std::string listed;
    for (const char *name : names) {
      if (strcmp(arg[iarg + k], name) == 0) return index;
      listed += (index == 0 ? "" : index + 1 == static_cast<int>(names.size()) ? " or " : ", ");
      listed += name;
      ++index;
    }
    fail("{} must be {}, not '{}'", arg[iarg], listed, arg[iarg + k]);
  }
  // NAME of the k-th value d_NAME: a per-atom weight (fix property/atom d_NAME), found by sediment_find_weights.
  std::string weight(int k) const
  {
    if (!has(k) || strncmp(arg[iarg + k], "d_", 2) != 0 || !arg[iarg + k][2])
      fail("'{}' needs a per-atom property d_NAME (fix property/atom d_NAME)", arg[iarg]);
    return arg[iarg + k] + 2;
  }
  // 0, 1, 2 for x, y, z; `what` names the axis in the error ("floor axis").
  int axis(int k, const char *what) const
  {
    const int dim = sediment_axis(arg[iarg + k]);
    if (dim < 0) fail("{} must be x, y or z, not '{}'", what, arg[iarg + k]);
    return dim;
  }
  [[noreturn]] void unknown(const char *expected) const
  {
    fail("unknown keyword '{}' (expected {})", arg[iarg], expected);
  }

  template <typename... Args> [[noreturn]] void fail(const std::string &format, Args &&...args) const
  {
    lmp->error->all(file, line, style + ": " + format, std::forward<Args>(args)...);
    __builtin_unreachable();    // error->all exits or throws; its formatting overload is not marked so
  }

 private:
  LAMMPS *lmp;
  const char *file;
  int line;
  std::string style;
  int narg;
  char **arg;
  int iarg;
};

// The simulated time at the current step: LAMMPS's elapsed time, which follows changes of the timestep
// between runs (it is not step x dt).
inline double sediment_time_now(const Update *update)
{
  return update->atime + static_cast<double>(update->ntimestep - update->atimestep) * update->dt;
}

// The fixes of a given style (e.g. every "fluid/drag").
inline std::vector<Fix *> sediment_fixes_of_style(LAMMPS *lmp, const char *style)
{
  std::vector<Fix *> found;
  sediment_for_each_fix(lmp->modify, [&](Fix *fix) {
    if (strcmp(fix->style, style) == 0) found.push_back(fix);
  });
  return found;
}

// Fix `id`, which must be of class T (style `style`); `caller` names the style asking ("Fix fluid/drag")
// and `role` what the fix is for ("fluid", "gravity").
template <class T>
T *sediment_find_fix(LAMMPS *lmp, const char *id, const char *style, const std::string &caller, const char *role)
{
  Fix *fix = sediment_fix_by_id(lmp->modify, id);
  if (!fix) lmp->error->all(FLERR, "{}: {} fix '{}' does not exist", caller, role, id);
  auto typed = dynamic_cast<T *>(fix);
  if (!typed || strcmp(fix->style, style) != 0)
    lmp->error->all(FLERR, "{}: fix '{}' is a fix {}, not a fix {}", caller, id, fix->style, style);
  return typed;
}

// The acceleration vector of fix gravity `id`, or of the deck's only fix gravity when `id` is null;
// `caller` names the style asking and `choose` tells how to choose among several.
inline const double *sediment_find_gravity(LAMMPS *lmp, const char *id, const std::string &caller, const char *choose)
{
  Fix *fix = nullptr;
  if (id) {
    fix = sediment_find_fix<Fix>(lmp, id, "gravity", caller, "gravity");
  } else {
    const auto gravities = sediment_fixes_of_style(lmp, "gravity");
    if (gravities.size() > 1) lmp->error->all(FLERR, "{}: several fix gravity are defined; {}", caller, choose);
    if (gravities.empty())
      lmp->error->all(FLERR, "{} needs a fix gravity to know the direction and strength of gravity", caller);
    fix = gravities.front();
  }
  int dim = 0;
  const auto *gravity = static_cast<const double *>(fix->extract("gvec", dim));
  if (!gravity) lmp->error->all(FLERR, "{}: fix gravity does not expose its vector", caller);
  return gravity;
}

// Compute `id` (a leading "c_" is dropped); `caller` names the style asking.
inline Compute *sediment_find_compute(LAMMPS *lmp, const char *id, const std::string &caller)
{
  const char *name = strncmp(id, "c_", 2) == 0 ? id + 2 : id;
  Compute *compute = sediment_compute_by_id(lmp->modify, name);
  if (!compute) lmp->error->all(FLERR, "{}: compute '{}' does not exist", caller, name);
  return compute;
}

// The index of the per-atom weight d_`name` (real spheres each atom stands for), checked > 0 and
// finite on every atom of `groupbit`: a weight of zero (a data file cut before its weights, which
// then read as zero) would make spheres vanish without a sign. `caller` names the style asking.
inline int sediment_find_weights(LAMMPS *lmp, const std::string &name, int groupbit, const std::string &caller)
{
  Atom *atom = lmp->atom;
  int is_double = 0, cols = 0;
  const int index = atom->find_custom(name.c_str(), is_double, cols);
  if (index < 0 || !is_double || cols != 0)
    lmp->error->all(FLERR, "{}: weight d_{} is not a per-atom floating-point vector (define it with fix "
                    "property/atom d_{})", caller, name, name);
  const double *weight = atom->dvector[index];
  bigint bad = 0, all_bad = 0;
  tagint first = MAXTAGINT, all_first = 0;
  for (int i = 0; i < atom->nlocal; ++i)
    if ((atom->mask[i] & groupbit) && !(weight[i] > 0.0 && std::isfinite(weight[i]))) {
      ++bad;
      first = std::min(first, atom->tag[i]);
    }
  MPI_Allreduce(&bad, &all_bad, 1, MPI_LMP_BIGINT, MPI_SUM, lmp->world);
  MPI_Allreduce(&first, &all_first, 1, MPI_LMP_TAGINT, MPI_MIN, lmp->world);
  if (all_bad > 0)
    lmp->error->all(FLERR, "{}: {} atoms have a weight d_{} that is not > 0 (atom {} the first): did the data file "
                    "lose its weights section, or were they never set?", caller, all_bad, name, all_first);
  return index;
}

}    // namespace LAMMPS_NS

#endif
