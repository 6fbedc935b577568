"""Simulated instruments that close the loop without a lab: the flow-reactor (C60 adduct) BNN emulator and the
redox-candidate lookup. No ROS here. Each has `parameters`, `outputs` and `measure(params) -> {output: value}`."""

from .flow_reactor import FlowReactorEmulator, FlowReactorResult
from .redox import RedoxEmulator

__all__ = ["FlowReactorEmulator", "FlowReactorResult", "RedoxEmulator"]
