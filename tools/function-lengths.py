#!/usr/bin/env python3
# Issue 53's structure figures: product functions over 80 lines (fn line to closing brace, outside
# tests/, benches/, examples/ and #[cfg(test)] modules) and product files over 1 000 lines.
#   python3 tools/function-lengths.py [ROOT]
import re,sys,os
# Rough: product .rs files (not tests/, benches/, examples/, fuzz/), skipping #[cfg(test)] modules.
res=[];files=[]
for root,dirs,fs in os.walk(sys.argv[1] if len(sys.argv)>1 else '.'):
    if any(p in root for p in ['/target','/tests','/benches','/examples','/fuzz','/.git']): continue
    for f in fs:
        if f.endswith('.rs'): files.append(os.path.join(root,f))
for f in files:
    L=open(f).read().split('\n')
    # cut test modules
    end=len(L)
    for i,l in enumerate(L):
        if l.startswith('#[cfg(test)]'): end=i;break
    prod=end
    i=0
    while i<end:
        m=re.match(r'^(\s*)(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?fn\s+(\w+)',L[i])
        if m:
            ind=len(m.group(1)); name=m.group(7)
            # find body open
            j=i; depth=0; started=False
            while j<end:
                for ch in L[j]:
                    if ch=='{': depth+=1; started=True
                    elif ch=='}': depth-=1
                if started and depth==0: break
                if not started and L[j].rstrip().endswith(';'): break
                j+=1
            if started: res.append((j-i+1,f,name,i+1))
            i=j+1 if started else i+1
        else: i+=1
    files_len=prod
    print('FILE',prod,f) if prod>1000 else None
res.sort(reverse=True)
print('over 80:',sum(1 for r in res if r[0]>80),' over 120:',sum(1 for r in res if r[0]>120))
for r in res:
    if r[0]>80: print(r)
