import json,sys,statistics as st,collections
for f in sys.argv[1:]:
  d=collections.defaultdict(list); init=[]
  recs=[json.loads(l) for l in open(f)]
  # images where at least one method is correct (the thesis's filter)
  ok_img={r['im_id'] for r in recs if r['correct']}
  for r in recs: d[r['refinement']].append(r)
  print('==',f.split('/')[-2], f'images with >=1 correct: {len(ok_img)}/{len({r["im_id"] for r in recs})}')
  for k in ['icp','icp_lm','icp_plane','gicp','ndt']:
    v=[r for r in d[k] if r['im_id'] in ok_img]; c=[r for r in v if r['correct']]
    te=[r['errors']['translation_mm'] for r in c]; rr=[r['errors']['rotation_1mpq'] for r in c]
    if not te: print(k,'0 correct'); continue
    print(f"{k:9s} {len(c)}/{len(v)}  t-err mean {st.mean(te):6.2f} std {st.pstdev(te):6.2f} (sample sd {st.stdev(te) if len(te)>1 else 0:6.2f}) max {max(te):6.2f}  rot mean {st.mean(rr):.4f} std {st.pstdev(rr):.4f}  time {st.mean(r['times']['total'] if 'total' in r['times'] else sum(r['times'].values()) for r in v):.2f}s")
