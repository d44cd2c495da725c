// The page: wires the library, the stage (panes, transport, curve plot), search and labels to
// the state they share: the space, the open clip, the selected range, the last search.
import { api, type FrameRange } from "./api/routes";
import { bytesToBase64 } from "./api/packed";
import type { Clip, IngestClipResponse, SearchResult, Space } from "./api/types";
import { isLive, watchJob } from "./controller/job_watch";
import { describe, fileQuery, toSearchQuery, type Query } from "./controller/search_query";
import { holds, loadSide, skeletonsOf, wholeClip } from "./controller/side_loader";
import { readDeepLink, showDeepLink, formatDeepLink, type DeepLink } from "./model/deep_link";
import { straightFrames, warpedFrames } from "./model/frame_map";
import type { Side } from "./player/stage_player";
import type { Stage } from "./stage";
import { byId, fill, h } from "./view/dom";
import { LabelPanel } from "./view/label_panel";
import { LibraryPanel } from "./view/library_panel";
import { SearchPanel } from "./view/search_panel";
import { SkeletonPanel } from "./view/skeleton_panel";
import { StatusLine } from "./view/status_line";

const MAX_RESULTS = 20;

export class App {
  private readonly status = new StatusLine(byId("status"));
  private readonly library = new LibraryPanel(byId("library"), this.status);
  private readonly search = new SearchPanel(byId("search"));
  private readonly labels = new LabelPanel(byId("labels"));
  private readonly skeleton = new SkeletonPanel(byId("skeleton"));
  private readonly spaceSelect = byId<HTMLSelectElement>("space");
  private stageLoad: Promise<Stage> | null = null;
  private spaces: Space[] = [];
  private openClip: Clip | null = null;
  private selection: FrameRange | null = null;
  private query: Query | null = null;
  private results: SearchResult[] = [];

  constructor() {
    this.library.onOpen = (clip) => this.run(this.open(clip));
    this.library.onAdd = (files) => this.run(this.add(files));
    this.search.onSearch = () => {
      const query = this.selectionQuery() ?? this.query;
      if (query) this.run(this.runSearch(query));
    };
    this.search.onFile = (file) => this.run(fileQuery(file).then((query) => this.runSearch(query)));
    this.search.onOpenHit = (index) => this.run(this.openHit(index));
    this.labels.onLabel = (descriptor, value) => this.run(this.addLabel(descriptor, value));
    this.labels.onPropagate = (descriptor, max) => this.run(this.propagate(descriptor, max));
    this.spaceSelect.addEventListener("change", () => this.showLink());
  }

  /** Loads the library and follows the page's address (a deep link). */
  async start(): Promise<void> {
    const [spaces, skeletons, info] = await Promise.all([
      api.spaces(),
      api.skeletons(),
      api.info(),
      this.library.reload(),
    ]);
    this.spaces = spaces;
    // What the token cannot do is not offered (the server refuses it all the same).
    this.labels.setWritable(info.scope !== "read");
    this.library.setWritable(info.scope !== "read");
    fill(
      this.spaceSelect,
      ...spaces.map((s) => {
        const skeletons = skeletonsOf(s);
        const which = `skeleton${skeletons.length > 1 ? "s" : ""} ${skeletons.join(", ")}`;
        return h("option", { value: s.name }, `${s.name} · ${which}`);
      }),
    );
    if (!spaces.length) fill(this.spaceSelect, h("option", { value: "" }, "no space"));
    this.library.showSkeletons(skeletons);
    document.body.dataset.ready = "true";
    performance.mark("motiondb-ready");
    void this.stage();
    await this.follow(readDeepLink(window.location.search));
  }

  private async follow(link: DeepLink): Promise<void> {
    if (link.space) {
      if (!this.spaces.some((s) => s.name === link.space))
        throw new Error(this.noSpace(link.space));
      this.spaceSelect.value = link.space;
    }
    if (!link.clipId) return;
    const clip = await api.clip(link.clipId);
    await this.open(clip, !link.space);
    if (link.from === undefined || link.to === undefined) return;
    this.select({ clipId: clip.clip_id, first: link.from, last: link.to });
    (await this.stage()).panes[0].timeline.select({ first: link.from, last: link.to });
    await this.runSearch({ kind: "range", clip, range: this.selection! });
    if (link.hit !== undefined && link.hit >= 1 && link.hit <= this.results.length)
      await this.openHit(link.hit - 1);
  }

  /** The stage, loaded on first use (three.js comes with it), its timelines wired to the page. */
  private stage(): Promise<Stage> {
    this.stageLoad ??= import("./stage").then(({ Stage }) => {
      const stage = new Stage();
      stage.panes.forEach((pane) => {
        pane.timeline.onSelect = (span) => {
          const clipId = pane.element.dataset.clipId;
          if (clipId) this.select({ clipId, first: span.first, last: span.last });
        };
      });
      stage.panes[0].timeline.onSeek = (frame) => stage.player.seekFrame(frame);
      return stage;
    });
    return this.stageLoad;
  }

  /** Why there is no space `name` to search in: it is unknown, or there is none at all. */
  private noSpace(name: string): string {
    if (!this.spaces.length)
      return "no space to search in: create one with `motiondb space create`";
    const known = this.spaces.map((s) => s.name).join(", ");
    return name
      ? `no space is named '${name}'; the spaces are: ${known}`
      : `choose a space to search in: ${known}`;
  }

  private get space(): Space | null {
    return this.spaces.find((s) => s.name === this.spaceSelect.value) ?? null;
  }

  /** Opens a clip alone on the stage; picks a space of its skeleton when the current one is not. */
  private async open(clip: Clip, pickSpace = true): Promise<void> {
    if (pickSpace && !holds(this.space, clip)) {
      const fitting = this.spaces.find((s) => holds(s, clip));
      if (fitting) this.spaceSelect.value = fitting.name;
    }
    this.status.info(`Opening ${clip.name}…`);
    const range = wholeClip(clip);
    const [side, skeleton] = await Promise.all([
      loadSide(
        {
          clip,
          range,
          frames: straightFrames(range.first, range.last, clip.fps),
          highlight: null,
          role: "clip",
        },
        this.space,
      ),
      api.skeleton(clip.skeleton_id),
    ]);
    this.skeleton.show(skeleton);
    this.openClip = clip;
    this.select(null);
    this.library.highlight(clip.clip_id);
    (await this.stage()).player.play([side], false);
    this.status.info(
      side.curve
        ? `${clip.name}: drag on the timeline to select a range`
        : `${clip.name}: no curve in space ${this.space?.name ?? "(none)"}`,
    );
  }

  /**
   * Adds files to the library one after another (the server reads FBX and glTF in a child
   * process of its own), then opens the first clip added. A file the server refuses stops the
   * rest; the ones before it stay added.
   */
  private async add(files: File[]): Promise<void> {
    const added: IngestClipResponse[] = [];
    try {
      for (const [i, file] of files.entries()) {
        this.status.info(`Adding ${file.name} (${i + 1} of ${files.length})…`);
        const bytes = new Uint8Array(await file.arrayBuffer());
        const answer = await api.ingest(file.name, bytesToBase64(bytes));
        added.push(answer, ...(answer.more_takes ?? []));
      }
    } finally {
      if (added.length) {
        this.library.showSkeletons(await api.skeletons());
        await this.library.reload();
      }
    }
    const first = added[0];
    if (!first) return;
    await this.open(first.clip);
    this.status.info(`added ${added.map((a) => a.clip.name).join(", ")}${facts(first)}`);
  }

  private select(range: FrameRange | null): void {
    this.selection = range;
    this.labels.setSelection(range !== null);
    const query = this.selectionQuery() ?? this.query;
    this.search.setQuery(query ? describe(query) : null);
    this.showLink();
  }

  /** A search with the selected range, when it is of a clip the page knows. */
  private selectionQuery(): Query | null {
    const range = this.selection;
    const clip = [this.openClip, this.query?.clip].find(
      (c) => c && range && c.clip_id === range.clipId,
    );
    return range && clip ? { kind: "range", clip, range } : null;
  }

  private showLink(): void {
    const range = this.selection;
    showDeepLink({
      space: this.space?.name,
      clipId: range?.clipId ?? this.openClip?.clip_id,
      from: range?.first,
      to: range?.last,
    });
  }

  private async runSearch(query: Query): Promise<void> {
    const space = this.space;
    if (!space) throw new Error(this.noSpace(this.spaceSelect.value));
    this.query = query;
    this.search.setQuery(describe(query));
    this.search.busy(`Searching ${describe(query)} in ${space.name}…`);
    const started = performance.now();
    const response = await api.search(space.name, toSearchQuery(query), MAX_RESULTS);
    this.results = response.results;
    const link =
      query.kind === "range"
        ? formatDeepLink({
            space: space.name,
            clipId: query.range.clipId,
            from: query.range.first,
            to: query.range.last,
          })
        : null;
    this.search.showResults(response.results, response.timings?.request_ms, link);
    document.body.dataset.searchMs = (performance.now() - started).toFixed(1);
    this.status.info(`${response.results.length} hits for ${describe(query)}`);
  }

  /** Opens hit `index` beside its query, both playing in step through the hit's warp path. */
  private async openHit(index: number): Promise<void> {
    const hit = this.results[index];
    const space = this.space;
    if (!hit || !this.query || !space?.report) return;
    const hitClip = await api.clip(hit.clip_id);
    const span = { first: hit.start_frame, last: hit.end_frame };
    const [query, hitSide] = await Promise.all([
      this.querySide(this.query, space),
      loadSide(
        {
          clip: hitClip,
          range: { clipId: hit.clip_id, ...span },
          frames: warpedFrames(hit.path, space.report.sample_rate),
          highlight: span,
          role: `hit ${index + 1}`,
        },
        space,
      ),
    ]);
    (await this.stage()).player.play([query, hitSide], true);
    this.search.highlight(index);
    this.status.info(`hit ${index + 1}: ${hit.clip_name} beside ${describe(this.query)}`);
  }

  /** The query's side: a stored range from the server, an uploaded file from the file. */
  private querySide(query: Query, space: Space): Promise<Side> {
    const { clip } = query;
    if (query.kind === "file") {
      const last = clip.frame_count - 1;
      return Promise.resolve({
        clip,
        poses: query.poses,
        labels: [],
        curve: null,
        frames: straightFrames(0, last, clip.fps),
        highlight: { first: 0, last },
        role: "query",
      });
    }
    const { first, last } = query.range;
    return loadSide(
      {
        clip,
        range: query.range,
        frames: straightFrames(first, last, clip.fps),
        highlight: { first, last },
        role: "query",
      },
      space,
    );
  }

  private async addLabel(descriptor: string, value: number): Promise<void> {
    if (!this.selection) return;
    await api.addLabel(this.selection, descriptor, value);
    this.status.info(
      `labelled frames ${this.selection.first}–${this.selection.last} ${descriptor}`,
    );
    await this.refreshLabels();
  }

  private async propagate(descriptor: string, maxResults: number): Promise<void> {
    const space = this.space;
    if (!space) throw new Error("no space to propagate in");
    const job = await watchJob(
      await api.startPropagation(space.name, descriptor, maxResults),
      (j) => this.labels.showJob(j),
    );
    if (!isLive(job)) await this.refreshLabels();
  }

  private async refreshLabels(): Promise<void> {
    for (const pane of (await this.stage()).panes) {
      const clipId = pane.element.dataset.clipId;
      if (clipId && !pane.element.hidden) pane.setLabels((await api.clipLabels(clipId)).labels);
    }
  }

  /** Runs an action, telling its failure in the status line. */
  private run(action: Promise<unknown>): void {
    action.catch((error) => this.status.error(error));
  }
}

/** What an added file said of itself: " (fbx · 0.01 m · Z up, stored Y up)". */
function facts(answer: IngestClipResponse): string {
  const file = answer.file;
  if (!file || file.format === "bvh") return "";
  const parts = [file.format];
  if (file.unit_m) parts.push(`${file.unit_m} m a unit`);
  if (file.up_axis) parts.push(file.up_axis === "Y" ? "Y up" : `${file.up_axis} up, stored Y up`);
  return ` (${parts.join(" · ")})`;
}
