// The one line at the bottom of the page that tells what the page is doing and what went wrong.
import { ApiError } from "../api/http";

export class StatusLine {
  constructor(private readonly element: HTMLElement) {}

  info(text: string): void {
    this.element.textContent = text;
    this.element.className = "status";
  }

  error(error: unknown): void {
    const text =
      error instanceof ApiError
        ? `${error.message} (HTTP ${error.status})`
        : error instanceof Error
          ? error.message
          : String(error);
    this.element.textContent = text;
    this.element.className = "status error";
  }
}
