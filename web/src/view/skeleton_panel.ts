// The open clip's skeleton and its humanoid map: which joint plays each canonical slot (the ones
// given by hand marked), the required slots no joint plays, and the left/right pairs that a
// mirrored search swaps. What lets motion of one rig be compared with another's.
import type { SkeletonDetail } from "../api/types";
import { h, fill } from "./dom";

export class SkeletonPanel {
  constructor(private readonly element: HTMLElement) {
    this.clear();
  }

  clear(): void {
    fill(this.element);
    this.element.hidden = true;
  }

  show(detail: SkeletonDetail): void {
    const { skeleton, humanoid_map: map } = detail;
    const missing = map.missing_slots ?? [];
    const pairs = map.mirror_pairs ?? [];
    fill(
      this.element,
      h("h2", {}, "Skeleton"),
      h(
        "div",
        { class: "summary", "data-testid": "skeleton-summary" },
        `${skeleton.name} · ${skeleton.joint_count} joints · `,
        map.complete ? "humanoid map complete" : `missing ${missing.join(", ")}`,
      ),
      h(
        "details",
        { "data-testid": "skeleton-map" },
        h("summary", {}, `${(map.slots ?? []).length} slots, ${pairs.length} mirror pairs`),
        h(
          "table",
          { class: "slot-table" },
          ...(map.slots ?? []).map((slot) =>
            h(
              "tr",
              { "data-slot": slot.slot },
              h("td", {}, slot.slot),
              h("td", {}, slot.joint_name, slot.overridden ? " (by hand)" : ""),
            ),
          ),
          ...missing.map((slot) =>
            h("tr", { class: "missing", "data-slot": slot }, h("td", {}, slot), h("td", {}, "—")),
          ),
        ),
        pairs.length
          ? h(
              "p",
              { class: "hint" },
              "Mirror pairs: ",
              pairs.map((p) => `${p.left_name}/${p.right_name}`).join(", "),
            )
          : null,
      ),
    );
    this.element.dataset.skeletonId = skeleton.skeleton_id;
    this.element.hidden = false;
  }
}
