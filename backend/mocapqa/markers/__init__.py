"""Optical marker QA: gaps, spikes, segments inferred from the take, label swaps and their
repair, label and static-marker checks, as pure numpy functions on ``(F, M, 3)`` positions."""
