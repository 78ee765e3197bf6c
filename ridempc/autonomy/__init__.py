"""Autonomy (the Hovershoes paper, sec. V): a depth camera on the rider, perception into an
occupancy map, Dijkstra and a timed elastic band, and ``ridempc navigate`` over courses."""

__all__: list[str] = []
