"""The benchmarks: scripts run from the repository root as modules (`python -m benchmarks.NAME`), importing each other
as `benchmarks.NAME`; results and the commands that produced them in benchmarks/README.md. Not installed with the
package. The task modules and adapters the peer harness loads (`portfolio_tasks`, `molecule_tasks`, `peers/`) are
also importable on their own, from the harness's PEER_PATH."""
