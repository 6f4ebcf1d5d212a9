"""Feet and ground: up axis and floor, foot contacts, and the findings on them (skate,
penetration, floating, jitter), as pure numpy functions on world positions of foot points."""
