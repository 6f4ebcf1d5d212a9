"""A shoot's heat map: joint × take share of frames outside the joint limits."""

from __future__ import annotations

from typing import Any

from mocapqa.store.shoot_pages import ShootPages, TakeFilter

__all__ = ["ShootHeatmap"]


class ShootHeatmap(ShootPages):
    """The heat map of a page of a shoot's take table (a part of
    :class:`~mocapqa.store.shoots.ShootStore`)."""

    def heatmap(
        self,
        shoot_id: str,
        limit: int = 200,
        offset: int = 0,
        sort: str = "score",
        descending: bool = False,
        filters: TakeFilter | None = None,
    ) -> dict[str, Any]:
        """Joint × take share of frames outside the limits, for a page of the shoot's takes
        (in the order and with the filters of :meth:`page`).

        Returns
        -------
        dict
            ``joints`` (those with any violation on the page, most violated first), ``takes``
            (``{"take_id", "name", "score"}`` in table order) and ``values`` (``joints × takes``
            shares in [0, 1]; 0 where none, None where the limits check did not run) and
            ``total`` (takes in the shoot that pass ``filters``).
        """
        page, total = self.page(shoot_id, limit, offset, sort, descending, filters)
        totals: dict[str, float] = {}
        for row in page:
            for joint, share in (row["joint_violations"] or {}).items():
                totals[joint] = totals.get(joint, 0.0) + float(share)
        joints = sorted(totals, key=lambda j: (-totals[j], j))
        values = [
            [
                (row["joint_violations"] or {}).get(joint, 0.0)
                if row["violation_share"] is not None
                else None
                for row in page
            ]
            for joint in joints
        ]
        return {
            "joints": joints,
            "takes": [
                {"take_id": r["take_id"], "name": r["name"], "score": r["score"]} for r in page
            ],
            "values": values,
            "total": total,
        }
