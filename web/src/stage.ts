// The stage: the two clip panes, the transport and the curve plot, on one clock. The page loads
// it after the library is on screen, since three.js is most of the page's code.
import { Clock } from "./player/clock";
import { StagePlayer } from "./player/stage_player";
import { ClipPane } from "./view/clip_pane";
import { CurvePlot } from "./view/curve_plot";
import { byId } from "./view/dom";
import { Transport } from "./view/transport";

const QUERY_COLOR = 0x4fb3ff;
const HIT_COLOR = 0xff9f43;

export class Stage {
  readonly clock = new Clock();
  readonly panes = [
    new ClipPane(byId("pane-a"), QUERY_COLOR),
    new ClipPane(byId("pane-b"), HIT_COLOR),
  ];
  readonly player = new StagePlayer(this.clock, this.panes, new CurvePlot(byId("curves")));

  constructor() {
    new Transport(byId("transport"), this.clock);
  }
}
