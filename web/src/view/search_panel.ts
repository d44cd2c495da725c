// Search: the query (the selected range of the open clip, or a dropped BVH, FBX or glTF file),
// the search button, and the ranked hits with score and time range. Choosing a hit opens it
// beside its query.
import type { SearchResult } from "../api/types";
import { score, seconds } from "../model/format";
import { h, fill } from "./dom";
import { dropZone, MOTION_FILES } from "./drop_zone";

export class SearchPanel {
  onSearch: () => void = () => {};
  onFile: (file: File) => void = () => {};
  onOpenHit: (index: number) => void = () => {};
  private readonly query = h("div", { class: "query", "data-testid": "query" });
  private readonly button = h("button", { class: "primary", "data-testid": "search" }, "Search");
  private readonly summary = h("div", { class: "summary", "data-testid": "search-summary" });
  private readonly hits = h("ol", { class: "hits", "data-testid": "hits" });

  constructor(element: HTMLElement) {
    const drop = dropZone({
      text: "Search with a BVH, FBX or glTF file: drop it here",
      accept: MOTION_FILES,
      multiple: false,
      testId: "drop",
      inputTestId: "query-input",
      onFiles: ([file]) => this.onFile(file),
    });
    fill(element, h("h2", {}, "Search"), this.query, this.button, drop, this.summary, this.hits);
    this.button.addEventListener("click", () => this.onSearch());
    this.setQuery(null);
  }

  /** What a search would ask: a sentence, or null when there is nothing to search with. */
  setQuery(description: string | null): void {
    this.query.textContent =
      description ?? "Open a clip and drag on its timeline to select a range.";
    this.button.disabled = description === null;
  }

  busy(what: string): void {
    this.summary.textContent = what;
    fill(this.hits);
  }

  showResults(results: SearchResult[], requestMs: number | undefined, link: string | null): void {
    const timing = requestMs === undefined ? "" : ` in ${requestMs.toFixed(1)} ms`;
    fill(
      this.summary,
      `${results.length} hits${timing}`,
      link
        ? h(
            "a",
            {
              href: link,
              class: "link",
              "data-testid": "search-link",
              title: "A link to this search",
            },
            "link",
          )
        : null,
    );
    fill(this.hits, ...results.map((result, i) => this.hit(result, i)));
  }

  /** Marks the hit open beside the query. */
  highlight(index: number): void {
    [...this.hits.children].forEach((row, i) => row.classList.toggle("open", i === index));
  }

  private hit(result: SearchResult, index: number): HTMLElement {
    const row = h(
      "li",
      { class: "hit", "data-testid": "hit", tabindex: 0 },
      h("span", { class: "rank" }, String(index + 1)),
      h("span", { class: "clip-name", title: result.clip_name }, result.clip_name),
      h(
        "span",
        { class: "score", title: "mean pose distance along the warp; lower is better" },
        score(result.score),
      ),
      h(
        "span",
        { class: "range" },
        `${seconds(result.start_s)} – ${seconds(result.end_s)} · frames ${result.start_frame}–${result.end_frame}`,
      ),
    );
    row.addEventListener("click", () => this.onOpenHit(index));
    row.addEventListener("keydown", (event) => {
      if (event.key === "Enter") this.onOpenHit(index);
    });
    return row;
  }
}
