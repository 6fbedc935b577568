"""Simulated instruments that close the loop without a lab: the flow-reactor (C60 adduct) emulator. No ROS here."""

from .flow_reactor import FlowReactorEmulator, FlowReactorResult

__all__ = ["FlowReactorEmulator", "FlowReactorResult"]
