#!/usr/bin/env python3
"""PPO for velocity tracking on the bundled Go1-class quadruped (train/README.md).

Proximal Policy Optimization (Schulman et al. 2017) with generalised advantage estimation
(Schulman et al. 2016), with the hyper-parameters of rsl_rl's PPO as legged_gym uses it
(24 steps per environment and iteration, 5 epochs of 4 mini-batches, clip 0.2, gamma 0.99,
lambda 0.95, entropy 0.01, learning rate 1e-3 adapted to a KL divergence of 0.01, gradient
norm 1, ELU MLPs, state-independent Gaussian std starting at 1), over the batched C++ rollout
(python/penumbra_rollout). Seeded: torch and the environment draw from the seed only.

Writes into --out: progress.csv (one row per iteration), curves.png (when matplotlib is
installed), checkpoint.pt and policy.onnx every --save-every-min minutes and at the end.

    PYTHONPATH=build/python:python nice /usr/bin/python3 train/ppo.py --out train/runs/go1 \
        --num-envs 64 --max-minutes 60 --seed 1
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import time

import numpy as np
import torch
import torch.nn as nn

_HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(_HERE), "python"))

from penumbra_rollout import QuadrupedEnvConfig, QuadrupedVelocityEnv  # noqa: E402
from penumbra_rollout.quadruped_env import ACT_DIM, OBS_DIM  # noqa: E402


def mlp(sizes, out):
    layers = []
    for a, b in zip(sizes[:-1], sizes[1:]):
        layers += [nn.Linear(a, b), nn.ELU()]
    layers.append(nn.Linear(sizes[-1], out))
    return nn.Sequential(*layers)


class ActorCritic(nn.Module):
    """Actor and critic MLPs (separate, ELU) and a learned per-action Gaussian std."""

    def __init__(self, hidden=(512, 256, 128), init_std=1.0):
        super().__init__()
        self.actor = mlp([OBS_DIM, *hidden], ACT_DIM)
        self.critic = mlp([OBS_DIM, *hidden], 1)
        self.log_std = nn.Parameter(torch.full((ACT_DIM,), float(np.log(init_std))))

    def dist(self, obs):
        mean = self.actor(obs)
        return torch.distributions.Normal(mean, self.log_std.exp().expand_as(mean))

    def value(self, obs):
        return self.critic(obs).squeeze(-1)


def export_onnx(model, path):
    """The actor's mean as ONNX: input 'obs' (1, 48) float32, output 'actions' (1, 12)."""
    actor = model.actor
    was_training = actor.training
    actor.eval()
    dummy = torch.zeros(1, OBS_DIM)
    cpu_actor = actor.to("cpu")
    tmp = path + ".tmp"
    kwargs = dict(input_names=["obs"], output_names=["actions"], opset_version=11,
                  do_constant_folding=True)
    try:
        # the TorchScript exporter (PyTorch >= 2.5 defaults to the dynamo one, opset >= 18,
        # which OpenCV 4.6 cannot read)
        torch.onnx.export(cpu_actor, dummy, tmp, dynamo=False, **kwargs)
    except TypeError:
        torch.onnx.export(cpu_actor, dummy, tmp, **kwargs)
    os.replace(tmp, path)
    actor.train(was_training)
    return cpu_actor


def plot_curves(csv_path, png_path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    rows = list(csv.DictReader(open(csv_path)))
    if not rows:
        return False
    x = np.array([float(r["env_steps"]) for r in rows]) / 1e6
    fig, ax = plt.subplots(2, 3, figsize=(14, 7))
    for a, keys, title in [
            (ax[0, 0], ["mean_episode_return"], "episode return"),
            (ax[0, 1], ["mean_episode_length_s"], "episode length (s)"),
            (ax[1, 0], ["rew_tracking_lin_vel", "rew_tracking_ang_vel"],
             "tracking reward per second (max 1.0 / 0.5)"),
            (ax[1, 1], ["action_std"], "policy std"),
            (ax[0, 2], ["mean_base_height"], "mean trunk height (m)"),
            (ax[1, 2], ["steps_per_s"], "policy steps / s")]:
        for k in keys:
            if k not in rows[0]:
                continue
            y = np.array([float(r[k]) if r[k] not in ("", "nan") else np.nan for r in rows])
            a.plot(x, y, label=k)
        a.set_title(title)
        a.set_xlabel("env steps (millions)")
        a.grid(True, alpha=0.3)
        if len(keys) > 1:
            a.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png_path, dpi=90)
    plt.close(fig)
    return True


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--num-envs", type=int, default=64)
    p.add_argument("--steps-per-env", type=int, default=24)
    p.add_argument("--iterations", type=int, default=100000)
    p.add_argument("--max-minutes", type=float, default=60.0, help="stop after this wall time")
    p.add_argument("--save-every-min", type=float, default=3.0)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--threads", type=int, default=0, help="physics threads (0 = all cores)")
    p.add_argument("--torch-threads", type=int, default=1)
    p.add_argument("--device", default="cpu", help="torch device for the networks: cpu, cuda")
    p.add_argument("--hidden", default="512,256,128")
    p.add_argument("--lr", type=float, default=1e-3)
    p.add_argument("--epochs", type=int, default=5)
    p.add_argument("--minibatches", type=int, default=4)
    p.add_argument("--resume", default="", help="checkpoint.pt to continue from")
    args = p.parse_args(argv)

    os.makedirs(args.out, exist_ok=True)
    torch.manual_seed(args.seed)
    torch.set_num_threads(max(1, args.torch_threads))
    dev = torch.device(args.device)
    hidden = tuple(int(h) for h in args.hidden.split(","))

    cfg = QuadrupedEnvConfig(num_threads=args.threads)
    env = QuadrupedVelocityEnv(args.num_envs, cfg, seed=args.seed)
    model = ActorCritic(hidden).to(dev)
    opt = torch.optim.Adam(model.parameters(), lr=args.lr)
    lr = args.lr
    it0, steps0, wall0 = 0, 0, 0.0
    if args.resume:
        ck = torch.load(args.resume, map_location=dev, weights_only=False)
        model.load_state_dict(ck["model"])
        opt.load_state_dict(ck["optimizer"])
        lr, it0, steps0, wall0 = ck["lr"], ck["iteration"], ck["env_steps"], ck["wall_s"]
        torch.manual_seed(args.seed + it0)
        env._seed(args.seed + it0)

    gamma, lam, clip, ent_coef, vf_coef, kl_target = 0.99, 0.95, 0.2, 0.01, 1.0, 0.01
    N, T = args.num_envs, args.steps_per_env
    obs_np, _ = env.reset()
    obs = torch.as_tensor(obs_np, device=dev)
    ep_ret = np.zeros(N)
    ep_len = np.zeros(N, dtype=np.int64)
    done_returns, done_lengths = [], []

    csv_path = os.path.join(args.out, "progress.csv")
    fields = ["iteration", "env_steps", "wall_s", "steps_per_s", "mean_reward",
              "mean_episode_return", "mean_episode_length_s", "rew_tracking_lin_vel",
              "rew_tracking_ang_vel", "mean_base_height", "action_std", "value_loss", "surrogate_loss", "lr", "kl"]
    new_csv = not (args.resume and os.path.exists(csv_path))
    csv_f = open(csv_path, "a" if not new_csv else "w", newline="")
    writer = csv.DictWriter(csv_f, fieldnames=fields)
    if new_csv:
        writer.writeheader()

    start = time.time()
    last_save = start

    def save(it, steps):
        ck = {"model": model.state_dict(), "optimizer": opt.state_dict(), "lr": lr,
              "iteration": it, "env_steps": steps, "wall_s": wall0 + time.time() - start,
              "hidden": hidden, "seed": args.seed, "num_envs": N, "argv": sys.argv}
        torch.save(ck, os.path.join(args.out, "checkpoint.pt.tmp"))
        os.replace(os.path.join(args.out, "checkpoint.pt.tmp"), os.path.join(args.out, "checkpoint.pt"))
        try:
            export_onnx(model, os.path.join(args.out, "policy.onnx"))
        except Exception as e:  # the checkpoint stays; train/export_onnx.py can export it later
            print(f"warning: ONNX export failed: {e}", flush=True)
        model.to(dev)
        csv_f.flush()
        plot_curves(csv_path, os.path.join(args.out, "curves.png"))

    b_obs = torch.zeros(T, N, OBS_DIM, device=dev)
    b_act = torch.zeros(T, N, ACT_DIM, device=dev)
    b_logp = torch.zeros(T, N, device=dev)
    b_val = torch.zeros(T, N, device=dev)
    b_rew = torch.zeros(T, N, device=dev)
    b_done = torch.zeros(T, N, device=dev)
    it = it0
    steps = steps0
    for it in range(it0 + 1, args.iterations + 1):
        t_it = time.time()
        sums_before = dict(env.episode_sums)
        height_sum = 0.0
        with torch.no_grad():
            for t in range(T):
                d = model.dist(obs)
                act = d.sample()
                b_obs[t] = obs
                b_act[t] = act
                b_logp[t] = d.log_prob(act).sum(-1)
                b_val[t] = model.value(obs)
                obs_np, rew, term, trunc, info = env.step(act.cpu().numpy())
                rew_t = torch.as_tensor(rew, device=dev)
                if trunc.any():
                    # time-outs bootstrap from the value of the last observation
                    fo = torch.as_tensor(info["final_observation"], device=dev)
                    rew_t = rew_t + gamma * model.value(fo) * torch.as_tensor(trunc, device=dev)
                b_rew[t] = rew_t
                done = term | trunc
                b_done[t] = torch.as_tensor(done, device=dev, dtype=torch.float32)
                ep_ret += rew
                ep_len += 1
                for i in np.nonzero(done)[0]:
                    done_returns.append(ep_ret[i])
                    done_lengths.append(ep_len[i])
                ep_ret[done] = 0.0
                ep_len[done] = 0
                obs = torch.as_tensor(obs_np, device=dev)
                height_sum += float(env.base_pos[:, 2].mean())
            last_val = model.value(obs)
            adv = torch.zeros(T, N, device=dev)
            gae = torch.zeros(N, device=dev)
            for t in reversed(range(T)):
                nxt = last_val if t == T - 1 else b_val[t + 1]
                nonterm = 1.0 - b_done[t]
                delta = b_rew[t] + gamma * nxt * nonterm - b_val[t]
                gae = delta + gamma * lam * nonterm * gae
                adv[t] = gae
            ret = adv + b_val
        steps += N * T

        # update
        f_obs, f_act = b_obs.reshape(-1, OBS_DIM), b_act.reshape(-1, ACT_DIM)
        f_logp, f_val = b_logp.reshape(-1), b_val.reshape(-1)
        f_adv, f_ret = adv.reshape(-1), ret.reshape(-1)
        f_adv = (f_adv - f_adv.mean()) / (f_adv.std() + 1e-8)
        B = f_obs.shape[0]
        mb = B // args.minibatches
        vl_sum = sl_sum = kl_sum = 0.0
        n_mb = 0
        for _ in range(args.epochs):
            perm = torch.randperm(B, device=dev)
            for k in range(args.minibatches):
                idx = perm[k * mb:(k + 1) * mb]
                d = model.dist(f_obs[idx])
                logp = d.log_prob(f_act[idx]).sum(-1)
                # adaptive learning rate on the KL divergence to the rollout policy (rsl_rl)
                approx_kl = float(((logp - f_logp[idx]).exp() - 1 - (logp - f_logp[idx])).mean())
                if approx_kl > kl_target * 2.0:
                    lr = max(1e-5, lr / 1.5)
                elif 0.0 < approx_kl < kl_target / 2.0:
                    lr = min(1e-2, lr * 1.5)
                for g in opt.param_groups:
                    g["lr"] = lr
                ratio = (logp - f_logp[idx]).exp()
                s1 = ratio * f_adv[idx]
                s2 = ratio.clamp(1 - clip, 1 + clip) * f_adv[idx]
                surr = -torch.min(s1, s2).mean()
                v = model.value(f_obs[idx])
                v_clip = f_val[idx] + (v - f_val[idx]).clamp(-clip, clip)
                vl = torch.max((v - f_ret[idx]) ** 2, (v_clip - f_ret[idx]) ** 2).mean()
                ent = d.entropy().sum(-1).mean()
                loss = surr + vf_coef * vl - ent_coef * ent
                opt.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(model.parameters(), 1.0)
                opt.step()
                vl_sum += float(vl)
                sl_sum += float(surr)
                kl_sum += approx_kl
                n_mb += 1

        wall = wall0 + time.time() - start
        secs = N * T * env.dt
        sums = {k: (env.episode_sums[k] - sums_before.get(k, 0.0)) / secs for k in env.episode_sums}
        row = {
            "iteration": it, "env_steps": steps, "wall_s": round(wall, 2),
            "steps_per_s": round(N * T / (time.time() - t_it), 1),
            "mean_reward": float(b_rew.mean()),
            "mean_episode_return": float(np.mean(done_returns[-200:])) if done_returns else "nan",
            "mean_episode_length_s": float(np.mean(done_lengths[-200:]) * env.dt) if done_lengths else "nan",
            "rew_tracking_lin_vel": sums.get("tracking_lin_vel", 0.0),
            "rew_tracking_ang_vel": sums.get("tracking_ang_vel", 0.0),
            "mean_base_height": height_sum / T,
            "action_std": float(model.log_std.exp().mean()),
            "value_loss": vl_sum / n_mb, "surrogate_loss": sl_sum / n_mb, "lr": lr,
            "kl": kl_sum / n_mb,
        }
        writer.writerow(row)
        if it % 10 == 0 or it == it0 + 1:
            csv_f.flush()
            print(f"it {it} steps {steps} wall {wall:.0f}s sps {row['steps_per_s']} "
                  f"ret {row['mean_episode_return']} len {row['mean_episode_length_s']} "
                  f"lin {row['rew_tracking_lin_vel']:.3f} ang {row['rew_tracking_ang_vel']:.3f} "
                  f"h {row['mean_base_height']:.3f} std {row['action_std']:.3f}", flush=True)
        done_returns = done_returns[-200:]
        done_lengths = done_lengths[-200:]
        now = time.time()
        if now - last_save > args.save_every_min * 60:
            save(it, steps)
            last_save = now
        if now - start > args.max_minutes * 60:
            break
    save(it, steps)
    csv_f.close()
    print(f"done: {it} iterations, {steps} env steps, {wall0 + time.time() - start:.0f} s", flush=True)


if __name__ == "__main__":
    main()
