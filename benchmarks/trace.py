"""One campaign of the default planner on a portfolio task, experiment by experiment: the point (option names, the
conditions), its result, and what made the proposal (the surrogate, and the rules in its `meta`: covering, settled,
stalled, within, off_bound). How the worst seeds of benchmarks/README.md's tables are traced.

    python -m benchmarks.trace --task m_oxidation --seed 2 [--scratch] [--hidden] [--budget N]
                               [--gp-after K [--at copper=CuOTf,bpy=1 ...]]

Without --scratch the campaign starts as the peer harness's does (`python -m benchmarks.portfolio ... --ours
default`): the task's initial points of that seed told first, so it is that run's campaign of the default planner,
experiment for experiment. With --scratch it is `python -m benchmarks.from_scratch`'s campaign of that seed (with
--hidden, under its hidden failures). The last line: the best result, and the plain regret (best - reference,
`from_scratch.REFERENCES`) where the task has a reference.

With --gp-after K the campaign stops after K experiments and prints the GP that the next ask fits to the successful
results (whichever surrogate the portfolio then picks; the ask then also believes failed experiments at its incumbent
and shifts its mean when the campaign has stalled, which this does not show): each Matern term's output scale and
its length scales by input (inputs in [0, 1]: a length scale far below the spacing of a parameter's levels makes each
level its own function), the noise, and for the best result so far and each --at point (the best result's point with
the given parameters changed, option names for categorical parameters) the posterior mean +- standard deviation and
log expected improvement in the GP's standardized units, and the true result.
"""

from __future__ import annotations

import argparse
import collections
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# the harness's `problems`, which the tasks build on (as in portfolio.py)
sys.path.insert(0, os.environ.get("PEERS_DIR", str(ROOT.parent / "shared" / "peers")))

from benchmarks import portfolio_tasks  # noqa: E402
from benchmarks.from_scratch import HIDDEN, REFERENCES, hidden_failure, steps  # noqa: E402

RULES = ("covering", "settled", "stalled", "within", "off_bound")  # the proposal meta keys of the default's rules


def describe(task, x: list) -> str:
    """A harness point as `name=value` pairs: option names for categorical parameters, conditions to 4 digits."""
    out = []
    for p, v in zip(task.params, x):
        if getattr(p, "categorical", False):
            out.append(f"{p.name}={p.options[int(v)]}")
        elif p.kind == "int":
            out.append(f"{p.name}={int(v)}")
        else:
            out.append(f"{p.name}={v:.4g}")
    return " ".join(out)


def campaign(task, seed: int, budget: int, scratch: bool, hidden: bool):
    """-> (the initial points told first: none with `scratch`, `from_scratch.steps` of the campaign, under the hidden
    failures with `hidden`)."""
    initial = [] if scratch else task.initial_points(seed)
    return initial, steps(task, seed, budget, lambda _, x: hidden and hidden_failure(task, x), initial)


def lines(task, seed: int, scratch: bool = False, hidden: bool = False, budget: int | None = None):
    """The campaign's lines as printed (see the module's docstring), the summary last."""
    initial, experiments = campaign(task, seed, budget or task.budget, scratch, hidden)
    best = math.inf
    for experiment, x, y, meta, _ in experiments:
        source = "initial" if experiment <= len(initial) else meta.get("surrogate", "")
        rules = " ".join(rule for rule in RULES if rule in meta)
        result = "failed" if y is None else f"{y:.4f}"
        best = best if y is None else min(best, y)
        yield f"{experiment:3d} {source:8s} {describe(task, x)}  {result}  {rules}".rstrip()
    summary = f"best {best:.4f}"
    if task.name in REFERENCES and math.isfinite(best):
        summary += f", regret {best - REFERENCES[task.name]:.4f}"
    yield summary


def input_names(features) -> list[str]:
    """The name of each GP input (`Features`): a parameter's name, with [k] for its k-th descriptor column and
    sin / cos for a periodic one's two."""
    space, names = features.space, []
    for kind, j, table in features.columns:
        if kind in ("continuous", "periodic"):
            name = space.names[int(space.cont_idx[j])]
            names += [f"{name} sin", f"{name} cos"] if kind == "periodic" else [name]
        else:
            name = space.names[int(space.finite_idx[j])]
            width = 1 if table is None else table.shape[1]
            names += [name] if width == 1 else [f"{name}[{k}]" for k in range(width)]
    return names


def gp_lines(task, seed: int, after: int, at: Sequence[str] = (), scratch: bool = False, hidden: bool = False):
    """The lines of --gp-after (see the module's docstring): the campaign's GP after `after` experiments."""
    import numpy as np
    import torch
    from gpytorch.kernels import MaternKernel, ScaleKernel

    from benchmarks.peers.gryffin_ros_peer import from_planner, option_names_of
    from gryffin_ros.planner.acquisition.gp import GPAcquisition

    # the last step's planner: the one after `after` results
    *_, planner = collections.deque(campaign(task, seed, after, scratch, hidden)[1], maxlen=1)[0]
    models = planner.surrogates()
    if models.density is None or len(models.successful) < 2:
        raise ValueError(f"after {after} experiments fewer than 2 have succeeded: no GP to show")
    gp = planner.surrogate_choice.gaussian_process(models.X, models.successful, models.descriptors)
    names = input_names(gp.features)
    yield f"GP after {after} experiments ({len(models.successful)} successful), standardized results:"
    modules = dict(gp.model.covar_module.named_modules())
    for path, kernel in modules.items():
        if not isinstance(kernel, MaternKernel):
            continue
        # its output scale: that of the innermost scale kernel around it (BoTorch's mixed GP nests them)
        scaled = [k for k, m in modules.items() if isinstance(m, ScaleKernel) and (k == "" or path.startswith(k + "."))]
        outputscale = modules[max(scaled, key=len)].outputscale.detach().item() if scaled else 1.0
        dims = (kernel.active_dims.tolist() if kernel.active_dims is not None
                else [i for i in range(gp.features.dim) if i not in gp.features.cat_dims])
        scales = kernel.lengthscale.detach().numpy().ravel()
        pairs = ", ".join(f"{names[d]} {v:.3g}" for d, v in zip(dims, scales))
        yield f"  Matern term, output scale {outputscale:.3g}: {pairs}"
    if gp.features.cat_dims:
        yield f"  categorical kernel (options alike or not) on {', '.join(names[d] for d in gp.features.cat_dims)}"
    yield f"  noise {gp.model.likelihood.noise.detach().reshape(()).item():.3g}"
    option_names = option_names_of(task, seed)
    index = {n: {o: i for i, o in enumerate(options)} for n, options in option_names.items()}
    best = models.successful[int(np.argmin(models.merits))]
    points = [("best result", dict(best.params))]
    for spec in at:
        params = dict(best.params)
        for pair in spec.split(","):
            name, _, value = pair.partition("=")
            if name not in params:
                raise ValueError(f"--at {spec!r}: unknown parameter {name!r}; the task's: {', '.join(params)}")
            kind = next(p.kind for p in task.params if p.name == name) if name not in option_names else "option"
            if kind == "option" and value not in option_names[name]:
                raise ValueError(f"--at {spec!r}: {name} has no option {value!r}; its options: "
                                 f"{', '.join(option_names[name])}")
            try:
                params[name] = value if kind == "option" else (int(value) if kind == "int" else float(value))
            except ValueError:
                raise ValueError(f"--at {spec!r}: {name} takes {'an integer' if kind == 'int' else 'a number'}, "
                                 f"not {value!r}") from None
        points.append((spec, params))
    acquisition = GPAcquisition(gp)
    for label, params in points:
        X = planner.space.to_internal([params])
        with torch.no_grad():
            mean, sigma = (float(v) for v in gp.posterior.mean_and_sigma(gp.features.of(X)))
        x = from_planner(task, params, index)
        truth = ("not allowed by the known constraints" if not task.feasible(x)
                 else "failed (hidden)" if hidden and hidden_failure(task, x) else f"{task.objective(x):.4f}")
        yield (f"{label}: {describe(task, x)}: mean {mean:.3f} +- {sigma:.3f} (best {gp.posterior.best:.3f}), "
               f"log EI {-float(acquisition.evaluate(X)[0]):.2f}, true result {truth}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--task", required=True, help="one of: " + ", ".join(portfolio_tasks.TASKS))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--scratch", action="store_true", help="from the planner's first proposal, no initial points")
    parser.add_argument("--hidden", action="store_true", help="the hidden failures of from_scratch.py")
    parser.add_argument("--budget", type=int, default=None, help="experiments in all (default: the task's)")
    parser.add_argument("--gp-after", type=int, default=None, metavar="K",
                        help="stop after K experiments and print the GP the next ask builds (see above)")
    parser.add_argument("--at", action="append", default=[], metavar="NAME=VALUE,...",
                        help="with --gp-after: the best result's point with these parameters changed")
    args = parser.parse_args()
    if args.task not in portfolio_tasks.TASKS:
        parser.error(f"unknown task {args.task!r}; choose from {', '.join(portfolio_tasks.TASKS)}")
    if args.hidden and args.task not in HIDDEN:
        parser.error(f"--hidden is defined for {', '.join(HIDDEN)} only")
    if args.budget is not None and args.budget < 1:
        parser.error("--budget must be at least 1")
    if args.at and args.gp_after is None:
        parser.error("--at needs --gp-after")
    if args.budget is not None and args.gp_after is not None:
        parser.error("--budget and --gp-after both end the campaign: give one")
    task = portfolio_tasks.TASKS[args.task]()
    if args.gp_after is not None:
        if args.gp_after < 2:
            parser.error("--gp-after must be at least 2")
        try:
            for line in gp_lines(task, args.seed, args.gp_after, args.at, args.scratch, args.hidden):
                print(line, flush=True)
        except ValueError as error:
            parser.error(str(error))
        return
    for line in lines(task, args.seed, args.scratch, args.hidden, args.budget):
        print(line, flush=True)


if __name__ == "__main__":
    main()
