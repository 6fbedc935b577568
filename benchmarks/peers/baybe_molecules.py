"""BayBE (Merck's Bayesian Back End) on tasks whose categorical parameters are molecules (benchmarks/molecule_tasks.py),
the way a BayBE user encodes them: a `SubstanceParameter` built from the SMILES with one of BayBE's chemical encodings
(MORDRED, BayBE's default, decorrelated as by default; or RDKIT2DDESCRIPTORS), or the options alone as a
`CategoricalParameter` (one-hot). Otherwise BayBE's defaults: the TwoPhaseMetaRecommender (random until data exist,
then its BotorchRecommender: GaussianProcessSurrogate, qLogEI), one recommendation per ask, no molecule measured twice,
the target minimized. One module per encoding: peer_baybe_mordred, peer_baybe_rdkit, peer_baybe_onehot.

Needs `baybe[chem]` in the peer's environment (`../shared/peers/install_peer.sh baybe`, then
`/tmp/peervenvs/baybe/bin/pip install "baybe[chem]==0.15.0"`)."""

from __future__ import annotations

import warnings

import baybe
import pandas as pd
from baybe import Campaign
from baybe.parameters import CategoricalParameter, SubstanceParameter
from baybe.searchspace import SearchSpace
from baybe.targets import NumericalTarget
from baybe.utils.random import set_random_seed

warnings.filterwarnings("ignore")

DEFAULT_SEEDS = {"btz57": range(10)}
VERSION = "baybe-" + baybe.__version__


class Adapter:
    encoding: str | None = None  # None: one-hot (CategoricalParameter)

    def __init__(self, task, seed):
        set_random_seed(seed)
        self.task = task
        # the options' names in this seed's run (molecule tasks name them uninformatively, in a new order each seed)
        self.labels = {p.name: p.labels(seed) if hasattr(p, "labels") else list(p.options) for p in task.params}
        parameters = []
        for p in task.params:
            if not getattr(p, "categorical", False):
                raise ValueError(f"{p.name}: this adapter knows categorical (molecular) parameters only")
            if self.encoding is not None and getattr(p, "smiles", None):
                parameters.append(SubstanceParameter(name=p.name, data=dict(zip(self.labels[p.name], p.smiles)),
                                                     encoding=self.encoding))
            else:
                parameters.append(CategoricalParameter(name=p.name, values=tuple(self.labels[p.name]),
                                                       encoding="OHE"))
        self.campaign = Campaign(searchspace=SearchSpace.from_product(parameters=parameters),
                                 objective=NumericalTarget("y", minimize=True),
                                 allow_recommending_already_measured=False)

    def tell(self, xs, ys):
        rows = [{**{p.name: self.labels[p.name][int(v)] for p, v in zip(self.task.params, x)}, "y": y}
                for x, y in zip(xs, ys) if y is not None]
        if rows:
            self.campaign.add_measurements(pd.DataFrame(rows))

    def ask(self):
        recommendation = self.campaign.recommend(batch_size=1)
        return [self.labels[p.name].index(recommendation[p.name].iloc[0]) for p in self.task.params]


def adapter(encoding: str | None) -> tuple[str, str, dict, type]:
    """(PEER, VERSION, DEFAULT_SEEDS, Optimizer) for the harness."""
    name = (encoding or "onehot").lower().replace("rdkit2ddescriptors", "rdkit")
    return f"baybe_{name}", VERSION, DEFAULT_SEEDS, type(f"Optimizer_{name}", (Adapter,), {"encoding": encoding})
