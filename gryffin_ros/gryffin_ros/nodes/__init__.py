"""Thin rclpy nodes: the planner node and the flow-reactor emulator node. They parse, validate, call and publish."""
