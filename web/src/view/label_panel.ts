// Labels: put a descriptor on the selected range, then spread it through the library with a
// propagation job and watch its progress.
import type { Job } from "../api/types";
import { h, fill } from "./dom";

export class LabelPanel {
  onLabel: (descriptor: string, value: number) => void = () => {};
  onPropagate: (descriptor: string, maxResults: number) => void = () => {};
  private readonly descriptor = h("input", {
    type: "text",
    placeholder: "descriptor, e.g. raise-arms",
    "data-testid": "descriptor",
  });
  private readonly value = h("input", {
    type: "number",
    min: 0,
    max: 1,
    step: 0.05,
    value: 1,
    title: "value in [0, 1]",
  });
  private readonly add = h("button", { "data-testid": "add-label" }, "Label selection");
  private readonly maxResults = h("input", {
    type: "number",
    min: 1,
    max: 100,
    value: 5,
    title: "hits per label",
  });
  private readonly propagate = h("button", { "data-testid": "propagate" }, "Propagate");
  private readonly progress = h("progress", { max: 1, value: 0 });
  private readonly state = h("span", { class: "job-state", "data-testid": "job-state" });
  private readonly readOnly = h(
    "p",
    { class: "hint", "data-testid": "read-only", hidden: true },
    "This token can only read: labels and propagation need a token of scope write.",
  );
  private writable = true;
  private hasSelection = false;

  constructor(element: HTMLElement) {
    fill(
      element,
      h("h2", {}, "Labels"),
      h("div", { class: "row" }, this.descriptor, this.value),
      h("div", { class: "row" }, this.add),
      h(
        "div",
        { class: "row" },
        h("span", { class: "hint" }, "hits per label"),
        this.maxResults,
        this.propagate,
      ),
      h("div", { class: "row job" }, this.progress, this.state),
      this.readOnly,
    );
    this.add.addEventListener("click", () => {
      if (this.text()) this.onLabel(this.text(), Number(this.value.value));
    });
    this.propagate.addEventListener("click", () => {
      if (this.text()) this.onPropagate(this.text(), Number(this.maxResults.value));
    });
    this.setSelection(false);
  }

  setSelection(hasSelection: boolean): void {
    this.hasSelection = hasSelection;
    this.add.disabled = !hasSelection || !this.writable;
    this.add.title = hasSelection ? "" : "Select a range on the timeline first";
  }

  /** Whether the token may write: a read-only one sees the controls off and says why. */
  setWritable(writable: boolean): void {
    this.writable = writable;
    this.propagate.disabled = !writable;
    this.readOnly.hidden = writable;
    this.setSelection(this.hasSelection);
  }

  showJob(job: Job): void {
    const total = Number(job.total);
    this.progress.max = Math.max(1, total);
    this.progress.value = Number(job.done);
    const state = job.state.replace("JOB_STATE_", "").toLowerCase();
    const detail = job.error ? `: ${job.error}` : `, ${job.labels_written} labels written`;
    this.state.textContent = `${job.job_id} ${state} ${job.done}/${total}${detail}`;
    this.state.dataset.state = state;
  }

  private text(): string {
    return this.descriptor.value.trim();
  }
}
